#!/usr/bin/env bash
# The GPU checks of issue 36 in one go, for a lent GPU machine (the `device` tool) or any
# CUDA machine: tests/test_cuda.py, then bench_bem_engines (Tamaas, torch on one CPU thread and
# torch on the GPU, same machine), then bench_devices' CUDA column. Each step has its own time
# limit, and everything it prints is kept in OUT_DIR, so a step cut short still reports.
#
#   bash benchmarks/gpu_checks.sh OUT_DIR [SECONDS_TESTS SECONDS_BEM SECONDS_DEVICES]
#
# Runs from the source tree (PYTHONPATH=src): nothing is built or installed.
set -u
out=${1:?usage: gpu_checks.sh OUT_DIR [seconds for tests, bem, devices]}
t_tests=${2:-180}
t_bem=${3:-200}
t_dev=${4:-200}
mkdir -p "$out"
export PYTHONPATH=$PWD/src${PYTHONPATH:+:$PYTHONPATH} PYTHONUNBUFFERED=1
{
  date -u
  nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader || true
  python3 -c 'import torch; print("torch", torch.__version__, "cuda", torch.cuda.is_available())'
  nproc
} 2>&1 | tee "$out/machine.txt"

timeout "$t_tests" python3 -m pytest -m cuda tests/test_cuda.py -p no:cacheprovider -q -rs \
  2>&1 | tee "$out/test_cuda.log"
echo "test_cuda exit ${PIPESTATUS[0]}" | tee -a "$out/test_cuda.log"

OMP_NUM_THREADS=1 timeout "$t_bem" python3 benchmarks/bench_bem_engines.py ${BEM_ARGS:-} \
  --grids 384 768 --loads 20 --threads 1 2>&1 | tee "$out/bem_engines.log"
cp benchmarks/results/bem_engines.md "$out/bem_engines.md" 2>/dev/null || true

timeout "$t_dev" python3 benchmarks/bench_devices.py --devices cuda --max-k 1000 \
  --out "$out/devices_cuda.md" 2>&1 | tee "$out/devices.log"
