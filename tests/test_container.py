"""The container recipes (Dockerfile, container/efish.def, container/install.sh) parse, and build what the sources pin.

No container daemon runs on these machines, so nothing is built here: small parsers read the instructions the
recipes use, and :func:`problems` compares what they install with the sources: Python of environment.yml, torch of
pyproject.toml from PyTorch's CPU index (no CUDA), the extras of the README's first install command, no other
version restated, and both images copying the same files, every one the package is built from (and .dockerignore
letting them in). The Snakefile's container directive must name the image the docs build, and the slurm-apptainer
profile must be the slurm profile plus the container settings. Each check is shown to fail on a recipe changed
the way it guards against (a torch pin, a Python, an extra, a CUDA index).
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
import textwrap

import pytest
import yaml

from .helpers import scratch_workflow
from .markdown import FENCE, REPO, simple_commands

#: The Dockerfile instructions the recipe may use (anything else is a typo or a new need to review).
DOCKER_INSTRUCTIONS = {"FROM", "ARG", "ENV", "COPY", "RUN", "WORKDIR", "LABEL", "CMD", "ENTRYPOINT"}
#: The sections of an Apptainer definition file (apptainer.org's user guide, "Definition Files").
APPTAINER_SECTIONS = {"setup", "files", "environment", "post", "runscript", "startscript", "test", "labels", "help",
                      "arguments"}
CPU_INDEX = "https://download.pytorch.org/whl/cpu"
RECIPES = {"dockerfile": "Dockerfile", "dockerignore": ".dockerignore", "definition": "container/efish.def",
           "install": "container/install.sh",
           "pyproject": "pyproject.toml", "environment": "environment.yml", "readme": "README.md",
           "snakefile": "Snakefile", "docs": "docs/getting-started.md", "lock": "container/requirements.lock"}
#: The extras the image installs beyond the README's: tensorboard, so that train.loggers=[csv,tensorboard] works in it.
IMAGE_EXTRAS = {"tensorboard"}


# ------------------------------------------------------------------ parsers


def dockerfile(text: str) -> list[tuple[str, str]]:
    """(INSTRUCTION, arguments) of each instruction, continuation lines joined, comments and blank lines dropped;
    ValueError for an instruction outside :data:`DOCKER_INSTRUCTIONS` or a file not starting with FROM (or ARG)."""
    logical, parts = [], []
    for line in text.splitlines():
        if not parts and (not line.strip() or line.lstrip().startswith("#")):
            continue
        parts.append(line.rstrip().removesuffix("\\").strip())
        if not line.rstrip().endswith("\\"):
            logical.append(" ".join(p for p in parts if p))
            parts = []
    if parts:
        raise ValueError("Dockerfile ends inside a continued line")
    out = []
    for line in logical:
        word, _, args = line.partition(" ")
        if word.upper() not in DOCKER_INSTRUCTIONS:
            raise ValueError(f"unknown Dockerfile instruction {word!r}")
        out.append((word.upper(), args.strip()))
    if not out or out[0][0] not in ("FROM", "ARG"):
        raise ValueError("a Dockerfile starts with FROM (or ARG)")
    return out


def definition(text: str) -> tuple[dict[str, str], dict[str, list[str]]]:
    """(header, sections) of an Apptainer definition file: the ``Key: value`` lines before the first ``%section``
    and each section's non-blank lines, stripped. ValueError for a header line that is not ``Key: value``, an
    unknown section, or a header without Bootstrap and From."""
    header: dict[str, str] = {}
    sections: dict[str, list[str]] = {}
    current = None
    for line in text.splitlines():
        if line.startswith("%"):
            current = line[1:].split()[0]
            if current not in APPTAINER_SECTIONS:
                raise ValueError(f"unknown Apptainer section %{current}")
            sections.setdefault(current, [])
        elif current is not None:
            if line.strip():
                sections[current].append(line.strip())
        elif line.strip():
            key, sep, value = line.partition(":")
            if not sep or not key.strip().isalnum():
                raise ValueError(f"not a header line of a definition file: {line!r}")
            header[key.strip().lower()] = value.strip()
    if not {"bootstrap", "from"} <= set(header):
        raise ValueError("a definition file's header names Bootstrap and From")
    return header, sections


def shell_variables(script: str) -> dict[str, str]:
    """The ``NAME=value`` assignments of a shell script (its first argument as ``$1``), values unquoted."""
    found = {"1": "$1"}
    for name, value in re.findall(r"^([A-Z_]+)=(\S+)\s*$", script, re.M):
        found[name] = shlex.split(value)[0].replace('"$1"', "$1")
    return found


def pip_installs(script: str) -> list[list[str]]:
    """The words of every ``pip install`` line of a shell script, its variables substituted."""
    variables = shell_variables(script)

    def substitute(word: str) -> str:
        return re.sub(r"\$\{?([A-Z_]+|1)\}?", lambda m: variables.get(m[1], m[0]), word)

    return [[substitute(w) for w in shlex.split(line)] for line in script.splitlines()
            if line.strip().startswith("pip install")]


def python_of_image(image: str) -> str | None:
    """The Python version of an official python image tag (``python:3.11-slim`` -> ``3.11``); None for another
    image."""
    m = re.fullmatch(r"(?:docker\.io/(?:library/)?)?python:(\d+\.\d+)[\w.-]*", image)
    return m[1] if m else None


def extras(spec: str) -> set[str]:
    """The extras of a pip requirement of a local folder (``.[a,b]`` -> {a, b}; ``.`` -> none)."""
    m = re.fullmatch(r"[^\[\]]+(?:\[([\w,-]*)\])?", spec)
    if not m:
        raise ValueError(f"not a requirement of a folder: {spec!r}")
    return {e for e in (m[1] or "").split(",") if e}


# ------------------------------------------------------------------ what the sources pin


def shown_commands(page: str) -> list[list[str]]:
    """The words of every simple command in the ``bash`` blocks of a Markdown page's text, in order."""
    return [words for m in FENCE.finditer(page) if m["info"].strip().startswith("bash")
            for words in simple_commands(textwrap.dedent(m["body"]))]


def readme_install(readme: str) -> str:
    """The requirement the README's first command installs (``pip install -e .`` -> ``.``)."""
    for words in shown_commands(readme):
        if words[:2] == ["pip", "install"]:
            return words[-1]
    raise ValueError("the README shows no pip install")


def torch_pin(pyproject: str) -> str:
    """The version pyproject.toml pins torch to (``torch==X``)."""
    import tomllib

    pins = [d for d in tomllib.loads(pyproject)["project"]["dependencies"] if re.match(r"torch\b", d)]
    m = re.fullmatch(r"torch==([\w.]+)", pins[0].replace(" ", "")) if len(pins) == 1 else None
    if not m:
        raise ValueError(f"pyproject does not pin torch with ==: {pins}")
    return m[1]


def build_inputs(pyproject: str) -> set[str]:
    """The top-level paths the package is built from: pyproject.toml, its readme, the wheel's package folders and
    its force-included trees (the config), plus the install recipe the images run."""
    import tomllib

    data = tomllib.loads(pyproject)
    wheel = data["tool"]["hatch"]["build"]["targets"]["wheel"]
    paths = [data["project"]["readme"], *wheel["packages"], *wheel.get("force-include", {})]
    return {"pyproject.toml", "container/install.sh", "container/requirements.lock",
            *(path.split("/")[0] for path in paths)}


def environment_python(environment: str) -> str:
    """environment.yml's Python (``python=3.11`` -> ``3.11``)."""
    deps = [d for d in yaml.safe_load(environment)["dependencies"] if isinstance(d, str) and d.startswith("python")]
    return deps[0].split("=", 1)[1]


def container_image(snakefile: str) -> str:
    """The image the Snakefile's global container directive names when $EFISH_IMAGE is unset."""
    m = re.search(r'^container:\s*os\.environ\.get\("EFISH_IMAGE",\s*"([^"]+)"\)\s*$', snakefile, re.M)
    if not m:
        raise ValueError("the Snakefile has no container directive of the expected form")
    return m[1]


def documented_sif(page: str) -> str:
    """The image file the docs' ``apptainer build <image> container/efish.def`` command builds."""
    built = [words[-2] for words in shown_commands(page)
             if words[:2] == ["apptainer", "build"] and words[-1] == "container/efish.def"]
    if len(built) != 1:
        raise ValueError(f"the docs show {len(built)} apptainer builds of container/efish.def, not one")
    return built[0]


# ------------------------------------------------------------------ the comparison


def python_problems(texts: dict[str, str]) -> list[str]:
    """Both images build on the official python image of environment.yml's Python."""
    python, found = environment_python(texts["environment"]), []
    for name, image in (("Dockerfile", dockerfile(texts["dockerfile"])[0][1]),
                        ("efish.def", definition(texts["definition"])[0]["from"])):
        if python_of_image(image) is None:
            found.append(f"{name} builds on {image}, not on an official python image")
        elif python_of_image(image) != python:
            found.append(f"{name} builds on Python {python_of_image(image)}, environment.yml has {python}")
    return found


def copy_problems(texts: dict[str, str]) -> list[str]:
    """Both images copy the same files, every one the package is built from, and run install.sh on them."""
    steps, (_, sections) = dockerfile(texts["dockerfile"]), definition(texts["definition"])
    found, installer = [], "container/install.sh"
    if not any(installer in args for kind, args in steps if kind == "RUN") or not any(
            installer in line for line in sections.get("post", [])):
        found.append(f"the Dockerfile and efish.def do not both run {installer}")
    copied = {w for kind, args in steps if kind == "COPY" for w in args.split()[:-1]}
    files = {line.split()[0] for line in sections.get("files", [])}
    if copied != files:
        found.append(f"the Dockerfile copies {sorted(copied)}, efish.def {sorted(files)}")
    if missing := build_inputs(texts["pyproject"]) - copied:
        found.append(f"the images lack what the package is built from: {sorted(missing)}")
    # .dockerignore leaves everything out (results/ can hold gigabytes) but what it lets in with "!"
    let_in = {line[1:] for line in texts["dockerignore"].splitlines() if line.startswith("!")}
    if left_out := copied - let_in:
        found.append(f".dockerignore leaves out what the Dockerfile copies: {sorted(left_out)}")
    return found


def pin_problems(texts: dict[str, str]) -> list[str]:
    """install.sh installs pyproject's torch pin from the CPU index, the checkout with the README's extras and
    :data:`IMAGE_EXTRAS`, and restates no other version."""
    installs, found = pip_installs(texts["install"]), []
    torch, pin = [w for words in installs for w in words if w.startswith("torch")], torch_pin(texts["pyproject"])
    if torch != [f"torch=={pin}"]:
        found.append(f"install.sh installs {torch}, pyproject pins torch=={pin}")
    for words in installs:
        if any(w.startswith("torch") for w in words) and words[words.index("--index-url") + 1:][:1] != [CPU_INDEX]:
            found.append(f"torch is not installed from the CPU index only: {' '.join(words)}")
    restated = [w for words in installs for w in words if re.search(r"[=<>~!]=|[<>]", w) and not w.startswith("torch")]
    if restated:
        found.append(f"install.sh restates pins pyproject owns: {restated}")
    package = [words[-1] for words in installs if words[-1].startswith("$1")]
    wanted = extras(readme_install(texts["readme"])) | IMAGE_EXTRAS
    if len(package) != 1 or extras(package[0].replace("$1", ".")) != wanted:
        found.append(f"install.sh installs the checkout as {package}, not with extras {sorted(wanted)}")
    return found


def lock_pins(lock: str) -> dict[str, str]:
    """The lock's ``NAME==VERSION`` lines as {normalised name: version}; ValueError for any other line."""
    from packaging.utils import canonicalize_name

    pins = {}
    for line in lock.splitlines():
        if line.strip() and not line.startswith("#"):
            m = re.fullmatch(r"([A-Za-z0-9][\w.-]*)==([\w.!+-]+)", line.strip())
            if not m:
                raise ValueError(f"a lock line is not NAME==VERSION: {line!r}")
            pins[canonicalize_name(m[1])] = m[2]
    return pins


def lock_python(lock: str) -> str | None:
    """The Python the lock was resolved on, from its header (``on Python 3.11.7``)."""
    m = re.search(r"on Python (\d+\.\d+\.\d+)", lock)
    return m[1] if m else None


def lock_problems(texts: dict[str, str]) -> list[str]:
    """The lock satisfies every dependency pyproject declares for the image (its dependencies and
    :data:`IMAGE_EXTRAS`), install.sh takes it as constraints, and both images build on the Python patch release
    it was resolved on."""
    import tomllib

    from packaging.requirements import Requirement
    from packaging.utils import canonicalize_name

    found, pins = [], lock_pins(texts["lock"])
    project = tomllib.loads(texts["pyproject"])["project"]
    wanted = [*project["dependencies"], *(d for e in IMAGE_EXTRAS for d in project["optional-dependencies"][e])]
    for spec in wanted:
        req = Requirement(spec)
        if req.marker is not None and not req.marker.evaluate():
            continue
        name = canonicalize_name(req.name)
        if name not in pins:
            found.append(f"the lock lacks {req.name} (pyproject: {spec}): run sh container/lock.sh")
        elif not req.specifier.contains(pins[name], prereleases=True):
            found.append(f"the lock's {req.name}=={pins[name]} does not satisfy pyproject's {spec}: run "
                         "sh container/lock.sh")
    constrained = [words for words in pip_installs(texts["install"])
                   if any(w.startswith("$1") for w in words) and "-c" in words]
    if not any(words[words.index("-c") + 1] == "$1/container/requirements.lock" for words in constrained):
        found.append("install.sh does not install the checkout with -c container/requirements.lock")
    python = lock_python(texts["lock"])
    for name, image in (("Dockerfile", dockerfile(texts["dockerfile"])[0][1]),
                        ("efish.def", definition(texts["definition"])[0]["from"])):
        if python is None or not re.fullmatch(rf"(?:docker\.io/(?:library/)?)?python:{re.escape(python)}-[\w.-]+",
                                              image):
            found.append(f"{name} builds on {image}, not on the Python {python} the lock was resolved on")
    return found


def cuda_problems(texts: dict[str, str]) -> list[str]:
    """Nothing the recipes execute names CUDA (their comments and the .def's help text may: they say "no CUDA")."""
    steps, (header, sections) = dockerfile(texts["dockerfile"]), definition(texts["definition"])
    executed = [args for _, args in steps] + list(header.values()) + [
        line for name in ("files", "post", "environment", "runscript") for line in sections.get(name, [])] + [
        line for line in texts["install"].splitlines() if not line.lstrip().startswith("#")]
    cuda = re.findall(r"whl/cu\d+|nvidia|cuda", "\n".join(executed), re.I)
    return [f"the recipes name CUDA: {sorted(set(cuda))}"] if cuda else []


def image_problems(texts: dict[str, str]) -> list[str]:
    """The Snakefile's container directive names the image the docs build."""
    image, documented = container_image(texts["snakefile"]), documented_sif(texts["docs"])
    return [] if image == documented else [f"the Snakefile's container directive names {image}, the docs build "
                                           f"{documented}"]


def problems(texts: dict[str, str]) -> list[str]:
    """Every way the recipes in ``texts`` (keys of :data:`RECIPES`) differ from what the sources pin; none: agree."""
    return [p for check in (python_problems, copy_problems, pin_problems, lock_problems, cuda_problems,
                            image_problems) for p in check(texts)]


@pytest.fixture(scope="module")
def texts() -> dict[str, str]:
    return {key: (REPO / path).read_text() for key, path in RECIPES.items()}


def test_the_recipes_install_what_the_sources_pin(texts):
    assert problems(texts) == []
    assert extras(readme_install(texts["readme"])) == set()  # the README's first command: pip install -e .
    assert lock_python(texts["lock"]) is not None and lock_python(texts["lock"]).startswith(
        environment_python(texts["environment"]) + ".")
    assert python_of_image(dockerfile(texts["dockerfile"])[0][1]) == "3.11" == environment_python(texts["environment"])


@pytest.mark.parametrize("key, old, new, expected", [
    ("install", "TORCH=2.13.0", "TORCH=2.12.0", "install.sh installs ['torch==2.12.0'], pyproject pins torch==2.13.0"),
    ("pyproject", '"torch==2.13.0"', '"torch==2.14.0"', "pyproject pins torch==2.14.0"),
    ("dockerfile", "FROM python:3.11.7-slim-bookworm", "FROM python:3.12-slim", "Dockerfile builds on Python 3.12"),
    ("dockerfile", "FROM python:3.11.7-slim-bookworm", "FROM python:3.11-slim",
     "Dockerfile builds on python:3.11-slim, not on the Python 3.11.7 the lock was resolved on"),
    ("lock", "\nnumba==", "\n# numba==", "the lock lacks numba"),
    ("lock", "\ntorch==2.13.0", "\ntorch==2.12.0", "the lock's torch==2.12.0 does not satisfy pyproject's torch==2.13.0"),
    ("install", '-c "$SOURCE/container/requirements.lock" ', "", "does not install the checkout with -c"),
    ("install", '"$SOURCE[tensorboard]"', '"$SOURCE"', "installs the checkout as ['$1'], not with extras ['tensorboard']"),
    ("dockerignore", "!container/requirements.lock\n", "",
     ".dockerignore leaves out what the Dockerfile copies: ['container/requirements.lock']"),
    ("environment", "python=3.11", "python=3.12", "efish.def builds on Python 3.11, environment.yml has 3.12"),
    ("install", '"$SOURCE[tensorboard]"', '"$SOURCE[slurm]"', "installs the checkout as ['$1[slurm]']"),
    ("install", "CPU_INDEX=https://download.pytorch.org/whl/cpu", "CPU_INDEX=https://download.pytorch.org/whl/cu128",
     "torch is not installed from the CPU index only"),
    ("install", '"$SOURCE[tensorboard]"', '"$SOURCE[tensorboard]" "numpy==2.0"',
     "install.sh restates pins pyproject owns: ['numpy==2.0']"),
    ("dockerfile", "FROM python:3.11.7-slim-bookworm", "FROM nvidia/cuda:12.8.0-runtime-ubuntu24.04",
     "the recipes name CUDA: ['cuda', 'nvidia']"),
    ("definition", "From: python:3.11.7-slim-bookworm", "From: ubuntu:24.04", "efish.def builds on ubuntu:24.04, not on an"),
    ("definition", "    src /opt/efish-src/src\n", "", "the Dockerfile copies"),
    ("dockerignore", "!config\n", "", ".dockerignore leaves out what the Dockerfile copies: ['config']"),
    ("pyproject", '"config" = "efish/_config"', '"config" = "efish/_config"\n"workflow" = "efish/_workflow"',
     "the images lack what the package is built from: ['workflow']"),
    ("snakefile", '"efish.sif")', '"efish-0.1.0.sif")', "the Snakefile's container directive names efish-0.1.0.sif"),
])
def test_each_check_catches_the_change_it_guards_against(texts, key, old, new, expected):
    assert old in texts[key]
    found = problems({**texts, key: texts[key].replace(old, new)})
    assert any(expected in p for p in found), found


def test_the_parsers_reject_what_they_do_not_know():
    assert dockerfile("# c\nFROM python:3.11-slim\nRUN a \\\n  b\n") == [("FROM", "python:3.11-slim"), ("RUN", "a b")]
    with pytest.raises(ValueError, match="unknown Dockerfile instruction 'RUNN'"):
        dockerfile("FROM python:3.11\nRUNN x\n")
    with pytest.raises(ValueError, match="starts with FROM"):
        dockerfile("RUN x\n")
    assert definition("Bootstrap: docker\nFrom: python:3.11\n%post\n  a\n\n  b\n") == (
        {"bootstrap": "docker", "from": "python:3.11"}, {"post": ["a", "b"]})
    with pytest.raises(ValueError, match="unknown Apptainer section %postt"):
        definition("Bootstrap: docker\nFrom: x\n%postt\n")
    with pytest.raises(ValueError, match="names Bootstrap and From"):
        definition("From: x\n%post\n")
    assert python_of_image("python:3.11-slim-bookworm") == "3.11" and python_of_image("ubuntu:24.04") is None
    assert extras(".[test,docs]") == {"test", "docs"} and extras(".") == set()


# ------------------------------------------------------------------ the profile and the workflow


def yte_profile(name: str) -> dict:
    """A profile's config.yaml as Snakemake reads it (YTE templates rendered), from the repository's root."""
    from yte import process_yaml

    cwd = os.getcwd()
    os.chdir(REPO)
    try:
        with open(REPO / "workflow/profiles" / name / "config.yaml") as f:
            return process_yaml(f)
    finally:
        os.chdir(cwd)


def test_the_apptainer_profile_is_the_slurm_profile_with_the_container_settings(monkeypatch):
    monkeypatch.delenv("EFISH_CONFIG_DIR", raising=False)
    slurm, apptainer = yte_profile("slurm"), yte_profile("slurm-apptainer")
    assert apptainer == {**slurm, "software-deployment-method": "apptainer",
                         "apptainer-args": f"--env EFISH_CONFIG_DIR={REPO / 'config'}"}


@pytest.mark.slow
def test_a_dry_run_with_the_apptainer_profile_plans_the_smoke_dag(tmp_path):
    """Snakemake accepts the profile's keys and the container directive (an apptainer stand-in answers its version
    check: no job runs in a dry run), and plans the same jobs as without containers."""
    work = scratch_workflow(tmp_path / "work")
    stub = tmp_path / "bin" / "apptainer"
    stub.parent.mkdir()
    stub.write_text("#!/bin/sh\n[ \"$1\" = --version ] && echo 'apptainer version 1.3.4' && exit 0\nexit 1\n")
    stub.chmod(0o755)
    env = {**os.environ, "EFISH_CONFIG_DIR": str(work / "config"),
           "PATH": f"{stub.parent}{os.pathsep}{os.environ['PATH']}"}

    def dry_run(*args: str) -> str:
        run = subprocess.run([sys.executable, "-m", "snakemake", "-n", "--config", "scale=smoke", *args], cwd=work,
                             env=env, capture_output=True, text=True, timeout=600)
        assert run.returncode == 0, run.stderr[-3000:]
        return run.stdout + run.stderr

    def jobs(output: str) -> dict[str, int]:
        """The dry run's job stats table: jobs per rule."""
        table = output[output.index("Job stats:"):].split("\n\n")[0]
        return {rule: int(n) for rule, n in re.findall(r"^(\w+)\s+(\d+)$", table, re.M)}

    planned = jobs(dry_run("--profile", "workflow/profiles/slurm-apptainer"))
    assert planned == jobs(dry_run("--cores", "1")) and planned["train"] == 2 and planned["total"] > 50
