"""Time per frame (003 §5.5.2): 003's ranking of the tracking threads beside our own stage times.

* :func:`source_timing_table` - what survives of 003 §5.5.2 (its table of times is a lost image): the
  ranking of SDVL, PTAM, SVO, LSD-SLAM and ORB-SLAM in words, and the "close to 40 % lower" without ORB;
* :func:`stage_timing_table` - our pipeline's milliseconds per frame, stage by stage, of runs already made.

We ran none of PTAM, SVO, LSD-SLAM or ORB-SLAM: no row of ours ranks against them. Timings depend on the
machine and its load; the notebook prints :func:`stage_timing_table` in a cell that nbval does not compare.
"""

from __future__ import annotations

from ..._table import format_table
from .runs import MonoRunResult
from .studies import table_notes

__all__ = ["MAPPING_STAGES", "SOURCE_TIMING", "TRACKING_STAGES", "source_timing_table", "stage_timing_table"]

#: 003 §5.5.2's tracking-thread times in words (its table is lost): system, rank (fastest 1), 003's words
SOURCE_TIMING = (
    ("SVO", "1", "the fastest: 'excellent results of a few milliseconds'"),
    ("SDVL (003's, no ORB)", "2", "'between the time efficiency of SVO and that of LSD-SLAM'"),
    ("LSD-SLAM", "3", "'an intermediate value between the two previous algorithms' (SVO, ORB-SLAM)"),
    ("ORB-SLAM", "4", "the slowest: 'in some cases a little above the values needed for real time'"),
    ("ORB-SDVL (003's, ORB)", "-", "slower than without ORB: without ORB 'times close to 40 % lower'"),
    ("PTAM", "-", "'hard to draw conclusions': it lost itself quickly in the hardest scenes"),
)

#: our stages of 003's tracking thread (§4.4 steps 2-4) and of its mapping thread (§4.2, §4.3)
TRACKING_STAGES = ("align", "match", "refine")
MAPPING_STAGES = ("detect", "mapping", "keyframe")


def source_timing_table() -> str:
    """003 §5.5.2's ranking of the tracking threads, in its words (the table of times is lost).

    Returns
    -------
    str
        One row per system, fastest first, and notes: what 003 measured, what "40 % lower" gives (ours),
        and the real-time budget we read from 003 §4.3 (ours).

    Examples
    --------
    >>> print(source_timing_table().splitlines()[0])
    003 §5.5.2: time of the tracking thread (ms per frame; its table is lost, its ranking survives)
    """
    rows = [list(r) for r in SOURCE_TIMING]
    ratio = 1.0 / (1.0 - 0.40)
    notes = [
        ("003 §5.5.2 times the tracking thread of each system in the six experiments of §5.5.1; it names no "
         "machine, and does not say which of the 3 runs of each (§5.5) its times come from."),
        (f"'40 % lower' (ours, arithmetic): with ORB the tracking takes 1 / (1 - 0.40) = {ratio:.2f} times as long; "
         "003 §5.4: ORB descriptors make SDVL 'slightly more accurate' and its tracking slower."),
        ("Real time (ours, a reading): 003 §4.3 counts 30 iterations as 1 second, i.e. 30 frames/s, "
         f"{1000 / 30:.1f} ms per frame; 003 §5.4: the tracking 'leaves room for real time on robots of low "
         "computing power'."),
    ]
    return format_table(["system", "rank", "003 §5.5.2 says"], rows,
                        title="003 §5.5.2: time of the tracking thread (ms per frame; its table is lost, its "
                              "ranking survives)") + "\n" + table_notes("Notes:", notes)


def stage_timing_table(runs: dict) -> str:
    """Our milliseconds per frame, stage by stage, of runs already made (ours; machine- and load-dependent).

    The tracking stages are 003 §4.4's steps 2-4 (``align``: sparse direct alignment; ``match``: the map
    projected and refined by Lucas-Kanade; ``refine``: the motion-only refinement), the tracking thread
    that 003 §5.5.2 times; the mapping stages (``detect``: FAST for the seeds' search; ``mapping``: the
    epipolar search and the depth filter; ``keyframe``: the keyframe rules) run in SDVL's other thread.
    Means over the tracked and lost frames (:meth:`~slamlab.mono.MonoSLAM.stage_times`).

    Parameters
    ----------
    runs : dict
        Label → :class:`~slamlab.studies.mono.MonoRunResult`.

    Returns
    -------
    str
        One row per run (its label should name the image size): the tracking stages and their sum, the
        mapping stages (the stage ``mapping`` headed ``seeds``) and their sum [ms per frame], and frames per
        second over the whole run.
    """
    if not isinstance(runs, dict) or not runs:
        raise TypeError(f"`runs` must be a non-empty dict of label -> MonoRunResult; got {type(runs).__name__}")
    rows = []
    for label, r in runs.items():
        if not isinstance(r, MonoRunResult):
            raise TypeError(f"`runs[{label!r}]` must be a MonoRunResult; got {type(r).__name__}")
        ms = {k: 1000.0 * v for k, v in r.stage_time_s.items()}
        track = sum(ms.get(k, 0.0) for k in TRACKING_STAGES)
        mapping = sum(ms.get(k, 0.0) for k in MAPPING_STAGES)
        rows.append([label,
                     *(f"{ms.get(k, 0.0):.1f}" for k in TRACKING_STAGES), f"{track:.1f}",
                     *(f"{ms.get(k, 0.0):.1f}" for k in MAPPING_STAGES), f"{mapping:.1f}", f"{r.fps:.0f}"])
    shown = {"mapping": "seeds"}  # the stage `mapping` (search and filter); "mapping" heads the thread's sum
    heads = ["run", *TRACKING_STAGES, "tracking", *(shown.get(k, k) for k in MAPPING_STAGES), "mapping", "frames/s"]
    return format_table(heads, rows, title="Our time per frame, ms (one thread in turn; this machine, this load)")
