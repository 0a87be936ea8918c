"""Compose the Hydra config tree and validate it against the schemas.

Uses Hydra's compose API only: no working-directory change, no timestamped
output folders. Every failure becomes a :class:`ConfigError` whose message is
one line naming the key.

A composition costs about 0.3 s, and a workflow parse composes a few dozen
(every job on a cluster parses the workflow again), so successful results are
kept on disk (:func:`cache_folder`), keyed by the overrides and a digest of
everything a composition reads: every file of the config tree, the sources of
this package's config modules and the Hydra and OmegaConf versions. Any edit
to one of them gives new keys; failures are never cached.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import re
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TypeVar

from .schema import ConfigError, EfishConfig, validate

_SCHEMA_REGISTERED = False
T = TypeVar("T")


def config_dir() -> Path:
    """Where the YAML config tree lives.

    ``$EFISH_CONFIG_DIR`` wins; then a copy shipped inside the package (wheel
    installs); then the repository's ``config/`` (editable installs).
    """
    env = os.environ.get("EFISH_CONFIG_DIR")
    candidates = [Path(env)] if env else []
    here = Path(__file__).resolve()
    candidates += [here.parent.parent / "_config", here.parents[3] / "config"]
    for path in candidates:
        if (path / "config.yaml").is_file():
            return path
    raise ConfigError(f"no config tree found (looked in {', '.join(map(str, candidates))}); set EFISH_CONFIG_DIR")


def cache_folder() -> Path | None:
    """Where composed configs are cached: ``$EFISH_CACHE_DIR/compose`` (``off`` or empty: no cache), else
    ``$XDG_CACHE_HOME/efish/compose`` (``~/.cache`` without it), beside numba's kernels."""
    env = os.environ.get("EFISH_CACHE_DIR")
    if env is not None and env.strip().lower() in ("", "off"):
        return None
    base = Path(env) if env else Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "efish"
    return base / "compose"


def _sources_digest() -> str:
    """Digest of this package's config sources (the schema the composed dataclasses come from) and the Hydra and
    OmegaConf versions, taken once, when this module is imported: a process whose schema.py was edited after it
    started still builds configs of the schema it loaded, so its cache entries must carry that schema's key."""
    import hydra
    import omegaconf

    digest = hashlib.sha256(f"hydra {hydra.__version__} omegaconf {omegaconf.__version__}".encode())
    for path in sorted(Path(__file__).parent.glob("*.py")):
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


_SOURCES_DIGEST = _sources_digest()


def _inputs_digest(tree: Path) -> str:
    """Digest of everything a composition reads: the config tree's files (computed afresh each time, a few ms: a
    tree edited between two compositions of one process must not be served the first result) and the sources
    this process loaded (:data:`_SOURCES_DIGEST`)."""
    digest = hashlib.sha256(_SOURCES_DIGEST.encode())
    for path in sorted(p for p in tree.rglob("*") if p.is_file()):
        digest.update(str(path.relative_to(tree)).encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def _cached(kind: str, overrides: Sequence[str], build: Callable[[], T], *extra: object) -> T:
    """``build()``, or its earlier result for the same ``kind``, overrides, ``extra`` and config inputs.

    The warnings ``build`` raised (a deprecated key, :func:`efish.config.schema.apply_renamed_keys`) are kept
    with the result and raised again on every hit: a cached composition warns as a fresh one does.
    """
    folder = cache_folder()
    if folder is None:
        return build()
    tree = config_dir().resolve()
    key = hashlib.sha256(repr((kind, str(tree), list(overrides), extra, _inputs_digest(tree))).encode()).hexdigest()
    path = folder / f"{key}.pkl"
    try:
        value, caught = pickle.loads(path.read_bytes())
    except Exception:  # absent, half-written by a killed process, or from an incompatible build: compose again
        caught = None
    if caught is None:
        value, caught = _recording_warnings(build)
        try:
            folder.mkdir(parents=True, exist_ok=True)
            tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
            tmp.write_bytes(pickle.dumps((value, caught)))
            os.replace(tmp, path)  # atomic: a concurrent reader sees the whole file or none
        except OSError:  # a read-only home is no reason to fail a composition
            pass
    for message, category, filename, lineno in caught:
        warnings.warn_explicit(message, category, filename, lineno)
    return value


def _recording_warnings(build: Callable[[], T]) -> tuple[T, list[tuple[str, type[Warning], str, int]]]:
    """``build()`` and the warnings it raised, as (message, category, filename, line), not yet shown."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        value = build()
    return value, [(str(w.message), w.category, w.filename, w.lineno) for w in caught]


def _register_schemas() -> None:
    """Register the dataclass schema so that Hydra type-checks and rejects unknown keys."""
    global _SCHEMA_REGISTERED
    if _SCHEMA_REGISTERED:
        return
    from hydra.core.config_store import ConfigStore

    ConfigStore.instance().store(name="efish_schema", node=EfishConfig)
    _SCHEMA_REGISTERED = True


def _hydra_compose(overrides: Sequence[str]):
    """The composed, unresolved DictConfig (Hydra's compose API); every failure one ConfigError line."""
    from hydra import compose as hydra_compose
    from hydra import initialize_config_dir
    from hydra.core.global_hydra import GlobalHydra

    _register_schemas()
    GlobalHydra.instance().clear()
    try:
        with initialize_config_dir(config_dir=str(config_dir()), version_base=None, job_name="efish"):
            return hydra_compose(config_name="config", overrides=list(overrides))
    except Exception as exc:  # Hydra and OmegaConf raise many types; all mean "bad config"
        raise ConfigError(one_line_message(exc)) from None
    finally:
        GlobalHydra.instance().clear()


def _to_config(raw) -> EfishConfig:
    from omegaconf import OmegaConf

    try:
        cfg = OmegaConf.to_object(raw)
    except Exception as exc:
        raise ConfigError(one_line_message(exc)) from None
    validate(cfg)
    return cfg


def compose_variants(overrides: Sequence[str], variants: dict[str, Sequence[str]] | None = None,
                     label: str = "variant") -> dict[str, EfishConfig]:
    """``compose(overrides + variant)`` for every variant, composing with Hydra only once.

    ``variants`` defaults to the composed config's own ``assay.conditions``.

    Hydra's compose costs about 0.13 s; an assay's conditions (30 for the bot
    assay) are mostly plain ``key=value`` overrides, which are applied to a copy
    of the composed config exactly as Hydra applies them. A variant that
    chooses a config group (``arena=npatch``) or adds or deletes keys is
    composed in full. Errors are one :class:`ConfigError` line naming the
    variant (``<label> <name>: ...``).
    """
    frozen = None if variants is None else {k: list(v) for k, v in variants.items()}
    return _cached("variants", overrides, lambda: _compose_variants(overrides, variants, label), frozen, label)


def _compose_variants(overrides: Sequence[str], variants: dict[str, Sequence[str]] | None,
                      label: str) -> dict[str, EfishConfig]:
    """:func:`compose_variants` without the cache."""
    from hydra.core.override_parser.overrides_parser import OverridesParser

    base = _hydra_compose(overrides)
    if variants is None:
        variants = _to_config(base).assay.conditions
    groups = {p.name for p in config_dir().iterdir() if p.is_dir()}
    parser = OverridesParser.create()
    out = {}
    for name, extra in variants.items():
        try:
            out[name] = _variant(base, parser, groups, overrides, extra)
        except ConfigError as exc:
            raise ConfigError(f"{label} {name}: {exc}") from None
    return out


def _variant(base, parser, groups: set[str], overrides: Sequence[str], extra: Sequence[str]) -> EfishConfig:
    """One variant of :func:`compose_variants`: Hydra's plain updates on a copy, or a full composition."""
    from omegaconf import OmegaConf

    try:
        parsed = parser.parse_overrides(list(extra))
    except Exception as exc:
        raise ConfigError(one_line_message(exc)) from None
    if any(o.is_add() or o.is_delete() or o.is_force_add() or o.key_or_group in groups or o.package for o in parsed):
        return compose(list(overrides) + list(extra))
    raw = base.copy()  # still in struct mode: an unknown key is an error, as in Hydra
    try:
        for o in parsed:
            OmegaConf.update(raw, o.key_or_group, o.value(), merge=True)
    except Exception as exc:
        raise ConfigError(one_line_message(exc)) from None
    return _to_config(raw)


def compose(overrides: Sequence[str] = ()) -> EfishConfig:
    """Compose ``config/config.yaml`` with Hydra overrides into a validated :class:`EfishConfig`.

    >>> cfg = compose(["physics.image_order=2"])
    >>> cfg.physics.image_order
    2
    """
    return _cached("config", overrides, lambda: _to_config(_hydra_compose(overrides)))


def one_line_message(exc: BaseException) -> str:
    """Reduce a Hydra/OmegaConf error (often multi-line, often chained) to one line naming the key."""
    text = str(exc)
    chain = exc.__cause__ or exc.__context__
    if chain is not None:
        text += "\n" + str(chain)
    key = re.search(r"full_key:\s*(\S+)", text)
    missing = re.search(r"Key '([^']+)' (?:is not in struct|not in '?\w+'?)", text)
    override = re.search(r"Could not override '([^']+)'", text)
    append = re.search(r"Could not append to config\. An item is already at '([^']+)'", text)
    name = (key or override or missing or append)
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    if "is not in struct" in text or "Key '" in text and "not in" in text:
        return f"unknown config key '{name.group(1) if name else '?'}'"
    option = re.search(r"Could not find '(\w+)/([^']+)'", text)
    if option is not None:
        group, choice = option.groups()
        known = sorted(p.stem for p in (config_dir() / group).glob("*.yaml"))
        return f"unknown {group} {choice!r}: choose one of {', '.join(known)} (files in config/{group}/)"
    if "Could not find" in text and "config" in text.lower():
        return lines[0]
    if name is not None:
        detail = next((ln for ln in lines if "Value" in ln or "type" in ln.lower()), lines[0])
        return f"bad value for '{name.group(1)}': {detail}"
    return lines[0] if lines else type(exc).__name__


def run_name(scale: str, overrides: Sequence[str]) -> str:
    """The name of a run's folders under ``results/`` and ``figures/``: the scale as shipped, else the scale and a
    short hash of the sorted overrides, so that two configs never share a folder.

    >>> run_name("laptop", []), run_name("laptop", ["train.lr=3e-4", "physics.tolerance=1e-6"])
    ('laptop', 'laptop-453280a3')
    """
    if not overrides:
        return scale
    digest = hashlib.sha256("\n".join(sorted(overrides)).encode()).hexdigest()[:8]
    return f"{scale}-{digest}"


def to_yaml(cfg: EfishConfig) -> str:
    """The resolved config as YAML, for ``config.yaml`` beside every output."""
    from omegaconf import OmegaConf

    return OmegaConf.to_yaml(OmegaConf.structured(cfg))
