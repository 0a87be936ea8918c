# The efish image for the cluster: Python 3.11 (environment.yml's; the patch release container/requirements.lock was
# resolved on), efish from this checkout with the lock's exact versions and the CPU build of torch (no CUDA). From the repository's root:
#   docker build -t efish:0.1.0 .
# container/efish.def builds the same image with Apptainer; both run container/install.sh, the one recipe.
# docs/getting-started.md#container says how the workflow runs its jobs in it.
FROM python:3.11.7-slim-bookworm

ENV PIP_DISABLE_PIP_VERSION_CHECK=1 \
    PIP_ROOT_USER_ACTION=ignore

# Only what the package is built from (pyproject.toml's readme, the sources, the config tree it ships), so
# results/ and figures/ never enter the image; .dockerignore keeps them out of the build context too.
COPY pyproject.toml README.md /opt/efish-src/
COPY src /opt/efish-src/src
COPY config /opt/efish-src/config
COPY container/install.sh /opt/efish-src/container/install.sh
COPY container/requirements.lock /opt/efish-src/container/requirements.lock
RUN sh /opt/efish-src/container/install.sh /opt/efish-src && rm -rf /opt/efish-src

CMD ["efish", "--help"]
