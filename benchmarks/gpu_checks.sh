#!/usr/bin/env bash
# The GPU checks of issues 36 and 38 in one go, for a lent GPU machine (the `device` tool) or
# any CUDA machine. Steps one after another (each timing has the GPU to itself), each
# time-limited, everything printed kept in OUT_DIR:
#   1. the machine's facts, then tests/test_cuda.py (correctness: CUDA against the CPU);
#   2. bench_bem_engines: one torch thread on the CPU, then the GPU, at 384^2 and 768^2;
#   3. bench_devices' CUDA column (dataset, epochs, designs with their BEM check, tolerance);
#   4. bench_design_device (device="auto" / "cuda" / "cpu"), if the deadline leaves time;
#   5. with TRAIN_BUDGET_S > 0: the adhesive networks' training (bench_adhesive_surrogate).
#
#   bash benchmarks/gpu_checks.sh OUT_DIR [TRAIN_BUDGET_S (0)] [DEADLINE_S (480)]
#
# Runs from the source tree (PYTHONPATH=src): nothing is built or installed. Seven files
# come back; training adds three, past the eight the device tool returns: run it on its own
# (a short DEADLINE_S skips steps 3 and 4).
set -u
out=${1:?usage: gpu_checks.sh OUT_DIR [training seconds a variant] [deadline seconds]}
budget=${2:-0}
deadline=${3:-480}
mkdir -p "$out"
export PYTHONPATH=$PWD/src${PYTHONPATH:+:$PYTHONPATH} PYTHONUNBUFFERED=1
left() { echo $((deadline - SECONDS)); }
{
  date -u
  nvidia-smi --query-gpu=name,memory.total,driver_version --format=csv,noheader || true
  python3 -c 'import torch; print("torch", torch.__version__, "cuda", torch.cuda.is_available())'
  nproc
} >"$out/facts.log" 2>&1

OMP_NUM_THREADS=1 timeout 240 python3 -m pytest -m cuda tests/test_cuda.py -p no:cacheprovider \
  -q -rs -n 0 --durations=5 >"$out/test_cuda.log" 2>&1
echo "test_cuda exit $? after ${SECONDS} s" >>"$out/test_cuda.log"

OMP_NUM_THREADS=1 timeout 120 python3 benchmarks/bench_bem_engines.py --grids 384 768 \
  --loads 20 --threads 1 --engines cpu gpu >"$out/bem.log" 2>&1
echo "bem exit $? after ${SECONDS} s" >>"$out/bem.log"
cp benchmarks/results/bem_engines.md "$out/bem_engines.md"

if [ "$(left)" -gt 60 ]; then
  OMP_NUM_THREADS=1 timeout "$(left)" python3 benchmarks/bench_devices.py --devices cuda \
    --max-k 10 --out "$out/devices.md" >"$out/devices.log" 2>&1
  echo "devices exit $? after ${SECONDS} s" >>"$out/devices.log"
fi

if [ "$(left)" -gt 60 ]; then
  CUBLAS_WORKSPACE_CONFIG=:4096:8 timeout "$(left)" python3 benchmarks/bench_design_device.py \
    --ks 1 30 >"$out/design_device.log" 2>&1
  echo "design_device exit $? after ${SECONDS} s" >>"$out/design_device.log"
fi

if [ "$budget" -gt 0 ]; then
  runs=/tmp/adhesive_runs
  OMP_NUM_THREADS=2 timeout $((budget * 2 + 150)) python3 benchmarks/bench_adhesive_surrogate.py \
    --out $runs --device cuda --budget "$budget" --eval-cells 2000 --variants window2 input \
    >"$out/adhesive.log" 2>&1
  for v in window2 input; do cp "$runs/$v/model.pt" "$out/adhesive_$v.pt" 2>/dev/null; done
fi
echo "done after ${SECONDS} s"
