"""``slamlab._heap.limit_heap_growth``: freed large arrays leave the process (a student's kernel in 512 MiB)."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from slamlab._heap import limit_heap_growth

# 50 arrays of 2 MiB with a small kept array after each, then the large ones freed. glibc, as it starts, maps a
# 16 MiB array on its own and raises its mmap threshold to 16 MiB when that array is freed, so the 2 MiB arrays
# then come from the heap, where the small ones pin them: about 100 MiB stay resident. With the fixed 256 KiB
# threshold each 2 MiB array is mapped on its own and unmapped when freed.
_PROBE = textwrap.dedent("""
    import sys
    import numpy as np
    if sys.argv[1] == "1":
        from slamlab._heap import limit_heap_growth
        assert limit_heap_growth()
    def rss_mib():
        return int(open("/proc/self/statm").read().split()[1]) * 4096 / 2**20
    a = np.ones(16 * 2**20 // 8)
    del a
    r0 = rss_mib()
    big, small = [], []
    for _ in range(50):
        big.append(np.ones(2 * 2**20 // 8))
        small.append(np.ones(512))
    del big
    print(rss_mib() - r0)
""")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt: Linux only")
def test_freed_large_arrays_leave_the_process_only_with_the_limit():
    def held(flag):
        out = subprocess.run([sys.executable, "-c", _PROBE, flag], capture_output=True, text=True, check=True)
        return float(out.stdout)

    assert held("0") > 50.0  # glibc as it starts: the freed arrays stay resident (the negative control)
    assert held("1") < 10.0


@pytest.mark.parametrize("kw", [{"arena_max": 0}, {"arena_max": 2.0}, {"arena_max": True},
                                {"mmap_threshold_bytes": 0}, {"mmap_threshold_bytes": 64 * 2**20}])
def test_bad_settings_are_refused(kw):
    with pytest.raises(ValueError, match=next(iter(kw))):
        limit_heap_growth(**kw)


def test_notebook_setup_applies_it():
    code = ("import slamlab as sl, slamlab._heap as h\n"
            "calls = []\n"
            "h.limit_heap_growth = lambda *a, **k: calls.append(1) or True\n"
            "sl.notebook_setup(show_versions=False)\n"
            "print(len(calls))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "1"


_FAULTS = textwrap.dedent("""
    import resource
    import numpy as np
    from slamlab._heap import limit_heap_growth, reuse_large_blocks
    assert limit_heap_growth()
    def faults(n=100):
        f0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        for _ in range(n):
            a = np.ones(2 * 2**20 // 8)
            del a
        return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - f0
    outside = faults()
    with reuse_large_blocks():
        with reuse_large_blocks():  # nested: counted
            inside = faults()
        nested_left = faults()
    after = faults()
    print(outside, inside, nested_left, after)
""")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt: Linux only")
def test_reuse_large_blocks_maps_no_fresh_pages_inside_and_restores_the_limit_after():
    out = subprocess.run([sys.executable, "-c", _FAULTS], capture_output=True, text=True, check=True)
    outside, inside, nested_left, after = map(int, out.stdout.split())
    # a 2 MiB array is 512 pages: under the limit each one is mapped afresh and faults its pages in
    assert outside > 100 * 400
    assert inside < 2000 and nested_left < 2000  # reused from the heap
    assert after > 100 * 400  # the limit is back


def test_reuse_large_blocks_does_nothing_without_the_limit():
    code = ("from slamlab import _heap\n"
            "with _heap.reuse_large_blocks():\n"
            "    print(_heap._STATE['depth'])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "0"
