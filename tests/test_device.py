"""The shared ``device`` option, as every device-taking function resolves it."""

import pytest
import torch

from metainterface import MetainterfaceError
from metainterface._device import resolve_device


def test_auto_is_cuda_only_when_torch_sees_it():
    expected = "cuda" if torch.cuda.is_available() else "cpu"
    assert resolve_device("auto").type == expected
    assert resolve_device().type == expected
    # small work (a design's refinement) stays on the CPU under "auto", on any machine
    assert resolve_device("auto", small=True).type == "cpu"
    assert resolve_device("cpu", small=True).type == "cpu"


def test_cpu_and_torch_device_pass_through():
    assert resolve_device("cpu") == torch.device("cpu")
    assert resolve_device(" CPU ") == torch.device("cpu")
    assert resolve_device(torch.device("cpu")) == torch.device("cpu")


@pytest.mark.parametrize("bad", ["gpu", "cuda:x", "", 3, None, "tpu:0"])
def test_bad_values_name_the_argument(bad):
    with pytest.raises(MetainterfaceError, match="device must be one of auto, cpu, cuda") as e:
        resolve_device(bad)
    assert e.value.argument == "device"


@pytest.mark.skipif(torch.cuda.is_available(), reason="this machine has CUDA")
def test_cuda_without_a_gpu_is_one_line():
    with pytest.raises(MetainterfaceError, match="no CUDA device") as e:
        resolve_device("cuda", name="device")
    assert "\n" not in str(e.value)
