"""slamlab._compiled: the one place that compiles kernels (issue 25)."""

import subprocess
import sys

import numpy as np

from slamlab._compiled import kernel, numba_enabled


def _sum_of_products(x, y):
    total = 0.0
    for i in range(x.shape[0]):
        total += x[i] * y[i]
    return total


def test_a_kernel_gives_the_python_functions_result_bit_for_bit():
    # no fastmath: the same sequential sum and the same roundings as the plain Python loop
    rng = np.random.default_rng(0)
    x, y = rng.standard_normal(1001), rng.standard_normal(1001)
    compiled = kernel(_sum_of_products)
    assert compiled(x, y) == _sum_of_products(x, y)
    assert compiled.py_func is _sum_of_products


def test_numba_is_used_unless_switched_off(monkeypatch):
    assert numba_enabled()
    monkeypatch.setenv("SLAMLAB_NO_NUMBA", "1")
    assert not numba_enabled()
    monkeypatch.setenv("SLAMLAB_NO_NUMBA", "0")
    assert numba_enabled()


def test_defining_a_kernel_does_not_import_numba(tmp_path):
    # compiling happens on the first call, so modules that define kernels keep `import slamlab` light
    (tmp_path / "mod.py").write_text("from slamlab._compiled import kernel\n@kernel\ndef f(x):\n    return x + 1\n")
    code = (
        "import sys, mod\n"
        "assert 'numba' not in sys.modules, 'imported at definition'\n"
        "assert mod.f(1) == 2 and 'numba' in sys.modules\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, cwd=tmp_path)


def test_popcount64_counts_bits_in_python_and_inside_a_kernel():
    """The one SWAR bit count the Hamming kernels share (``jitable``): plain Python and compiled give numpy's
    ``bitwise_count`` (the reference) on random and extreme words."""
    from slamlab.kdtree._hamming_kernel import all_hamming_2nn, popcount64

    rng = np.random.default_rng(0)
    words = np.r_[np.array([0, 1, 2**63, 2**64 - 1], dtype=np.uint64), rng.integers(0, 2**63, 200, dtype=np.uint64)]
    assert popcount64(words).tolist() == np.bitwise_count(words).tolist()
    # compiled: one word per descriptor, against the zero descriptor, so the distances are the bit counts
    d1 = all_hamming_2nn(words[:, None], np.zeros((1, 2), np.uint64))[1]
    assert d1.tolist() == np.bitwise_count(words).astype(float).tolist()


def test_hamming_words_is_the_bit_count_of_the_xor_in_python_and_inside_the_kernels():
    """The per-pair Hamming distance three kernels share (``jitable``): plain Python gives numpy's
    ``bitwise_count`` of the rows' XOR (the reference); compiled, the range kernel's nearest distance over one
    candidate is that count too."""
    from slamlab.kdtree._hamming_kernel import hamming_words, ranges_hamming_2nn

    rng = np.random.default_rng(1)
    Dq = rng.integers(0, 2**63, (20, 4), dtype=np.uint64)
    Dt = np.r_[rng.integers(0, 2**63, (19, 4), dtype=np.uint64), np.full((1, 4), 2**64 - 1, dtype=np.uint64)]
    ref = np.bitwise_count(Dq[:, None, :] ^ Dt[None, :, :]).sum(axis=2)
    with np.errstate(over="ignore"):  # numpy scalars warn on the bit count's intended wrap-around
        py = [[int(hamming_words(Dq, i, Dt, t)) for t in range(20)] for i in range(20)]
    assert py == ref.tolist()
    t = np.arange(20)[::-1].copy()  # query i's one candidate: target 19 - i
    d1 = ranges_hamming_2nn(Dq, Dt, t, np.arange(20), np.arange(1, 21))[1]
    assert d1.tolist() == ref[np.arange(20), t].astype(float).tolist()


def _scaled_sum(x, k):
    total = 0.0
    for i in range(x.shape[0]):
        total += k * x[i]
    return total


def test_first_calls_from_two_threads_make_one_dispatcher(monkeypatch):
    # two threads calling a kernel for the first time at once: without the first-call lock each made its own
    # dispatcher (compiled or loaded twice; loaded_kernels() listed it twice)
    import threading

    import numba

    from slamlab import _compiled

    made = []
    real_njit = numba.njit

    def counting_njit(*a, **k):
        made.append(1)
        return real_njit(*a, **k)

    monkeypatch.setattr(numba, "njit", counting_njit)
    compiled = kernel(_scaled_sum)
    x = np.arange(10.0)
    start = threading.Barrier(4)
    out = []

    def first_call():
        start.wait()
        out.append(compiled(x, 2.0))

    threads = [threading.Thread(target=first_call) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert out == [90.0] * 4
    assert len(made) == 1
    name = f"{_scaled_sum.__module__}.{_scaled_sum.__qualname__}"
    assert _compiled.loaded_kernels().count(name) == 1
