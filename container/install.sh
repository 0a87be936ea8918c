#!/bin/sh
# The one install recipe of the efish image, run by both the Dockerfile and container/efish.def, so the two
# images hold the same environment. Argument: the folder holding a copy of the checkout (pyproject.toml, README.md,
# src/, config/). Every pin but torch's comes from pyproject.toml through `pip install`; torch comes first from
# PyTorch's CPU wheel index, because PyPI's Linux wheel of torch pulls the CUDA libraries (gigabytes the cluster's
# CPU jobs never use), and pip then keeps it: 2.13.0+cpu satisfies pyproject's torch==2.13.0.
# tests/test_container.py checks that TORCH below equals pyproject's pin and that the extras equal the README's.
set -eu
SOURCE="$1"
TORCH=2.13.0
CPU_INDEX=https://download.pytorch.org/whl/cpu

pip install --no-cache-dir "torch==$TORCH" --index-url "$CPU_INDEX"
# not editable: the image keeps the package (and its config, efish/_config) and drops the source copy
pip install --no-cache-dir "$SOURCE"
# fails the build if the resolver swapped torch for another build
python -c "import torch; assert torch.__version__ == '$TORCH+cpu', torch.__version__; print('torch', torch.__version__)"
efish --help > /dev/null
