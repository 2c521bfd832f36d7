"""notebooks/conftest.py: nbval's kernel is started again when it dies before it is ready."""

import importlib.util
from pathlib import Path

import pytest
from nbval import kernel as nbval_kernel

CONFTEST = Path(__file__).resolve().parent.parent / "notebooks" / "conftest.py"


@pytest.fixture
def conftest_module():
    """notebooks/conftest.py loaded on its own; nbval's start_new_kernel restored afterwards."""
    saved = nbval_kernel.start_new_kernel
    spec = importlib.util.spec_from_file_location("notebooks_conftest_under_test", CONFTEST)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    yield mod
    nbval_kernel.start_new_kernel = saved


def test_a_kernel_that_dies_at_start_up_is_started_again(conftest_module, capsys):
    calls = []

    def dies_once(*args, **kwargs):
        calls.append(kwargs)
        if len(calls) == 1:
            raise RuntimeError("Kernel died before replying to kernel_info")
        return "km", "kc"

    conftest_module._start_new_kernel = dies_once
    assert nbval_kernel.start_new_kernel is conftest_module._start_new_kernel_again_if_it_died
    assert nbval_kernel.start_new_kernel(startup_timeout=5, kernel_name="k") == ("km", "kc")
    assert calls == [{"startup_timeout": 5, "kernel_name": "k"}] * 2
    assert "starting it again (2/3)" in capsys.readouterr().out


def test_a_kernel_that_never_starts_fails_after_three_tries(conftest_module):
    calls = []

    def always_dies(*args, **kwargs):
        calls.append(1)
        raise RuntimeError("Kernel died before replying to kernel_info")

    conftest_module._start_new_kernel = always_dies
    with pytest.raises(RuntimeError, match="Kernel died"):
        nbval_kernel.start_new_kernel()
    assert len(calls) == conftest_module.KERNEL_START_TRIES == 3
