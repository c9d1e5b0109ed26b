#!/usr/bin/env bash
# The GPU checks of issues 36 and 38 in one go, for a lent GPU machine (the `device` tool) or
# any CUDA machine. Steps, each time-limited, everything printed kept in OUT_DIR:
#   1. bench_bem_engines' GPU column alone (nothing else on the machine);
#   2. at once: the adhesive networks' training (bench_adhesive_surrogate: two processes on
#      the GPU), the Tamaas and one-thread torch columns of bench_bem_engines (CPU cores), and
#      tests/test_cuda.py (correctness only: its timings are not read);
#   3. bench_design_device (device="auto" / "cuda" / "cpu").
#
#   bash benchmarks/gpu_checks.sh OUT_DIR [TRAIN_BUDGET_S]
#
# Runs from the source tree (PYTHONPATH=src): nothing is built or installed. Seven files
# come back (the device tool returns at most eight): five logs and the two networks.
set -u
out=${1:?usage: gpu_checks.sh OUT_DIR [training seconds a variant]}
budget=${2:-200}
mkdir -p "$out"
export PYTHONPATH=$PWD/src${PYTHONPATH:+:$PYTHONPATH} PYTHONUNBUFFERED=1
{
  date -u
  nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader || true
  python3 -c 'import torch; print("torch", torch.__version__, "cuda", torch.cuda.is_available())'
  nproc
} >"$out/bem_gpu.log" 2>&1

OMP_NUM_THREADS=1 timeout 90 python3 benchmarks/bench_bem_engines.py --grids 384 768 \
  --loads 20 --engines gpu >>"$out/bem_gpu.log" 2>&1

runs=/tmp/adhesive_runs
OMP_NUM_THREADS=2 timeout $((budget * 2 + 150)) python3 benchmarks/bench_adhesive_surrogate.py \
  --out $runs --device cuda --budget "$budget" --eval-cells 2000 >"$out/adhesive.log" 2>&1 &
train=$!
OMP_NUM_THREADS=1 timeout $((budget * 2 + 100)) python3 benchmarks/bench_bem_engines.py \
  --grids 768 --loads 20 --threads 1 --engines tamaas cpu >"$out/bem_cpu.log" 2>&1 &
OMP_NUM_THREADS=1 timeout 240 python3 -m pytest -m cuda tests/test_cuda.py -p no:cacheprovider \
  -q -rs -n 0 >"$out/test_cuda.log" 2>&1
echo "test_cuda exit $?" >>"$out/test_cuda.log"
wait $train
for v in input curve; do cp "$runs/$v/model.pt" "$out/adhesive_$v.pt" 2>/dev/null; done
wait
CUBLAS_WORKSPACE_CONFIG=:4096:8 timeout 120 python3 benchmarks/bench_design_device.py \
  --ks 1 30 >"$out/design_device.log" 2>&1
echo done
