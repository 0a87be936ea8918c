#!/bin/sh
# The one install recipe of the efish image, run by both the Dockerfile and container/efish.def, so the two
# images hold the same environment. Argument: the folder holding a copy of the checkout (pyproject.toml, README.md,
# src/, config/, container/requirements.lock). Every version comes from container/requirements.lock, the exact
# resolution of pyproject.toml that container/lock.sh wrote, taken as pip constraints, so two builds hold the same
# packages; torch comes first from PyTorch's CPU wheel index, because PyPI's Linux wheel of torch pulls the CUDA
# libraries (gigabytes the cluster's CPU jobs never use), and pip then keeps it: 2.13.0+cpu satisfies the lock's
# torch==2.13.0. The tensorboard extra is in, so train.loggers=[csv,tensorboard] works in the image.
# tests/test_container.py checks that TORCH below equals pyproject's pin, that the lock satisfies pyproject, and
# that the extras are the README's plus tensorboard.
set -eu
SOURCE="$1"
TORCH=2.13.0
CPU_INDEX=https://download.pytorch.org/whl/cpu

pip install --no-cache-dir "torch==$TORCH" --index-url "$CPU_INDEX"
# not editable: the image keeps the package (and its config, efish/_config) and drops the source copy
pip install --no-cache-dir -c "$SOURCE/container/requirements.lock" "$SOURCE[tensorboard]"
# fails the build if the resolver swapped torch for another build
python -c "import torch; assert torch.__version__ == '$TORCH+cpu', torch.__version__; print('torch', torch.__version__)"
efish --help > /dev/null
