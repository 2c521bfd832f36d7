"""pytest set-up for the notebooks run under nbval (``make test``).

nbval (0.10, 0.11) sends each cell with ``store_history=False``. IPython decides
whether a trailing ``;`` silences a cell's result by reading the last *history*
entry, so under nbval ``sl.plotting.plot_slam_scheme();`` returns its ``Axes`` repr,
while Jupyter and nbclient (which wrote the stored outputs) show nothing: every
plotting cell would differ from its reference. Known and open upstream:
computationalmodelling/nbval#194 and ipython/ipython#14162. Until they are fixed,
nbval runs cells here the way Jupyter does, with history. Nothing else changes.
"""

from __future__ import annotations

import os

from nbval import kernel as _nbval_kernel

# The kernels nbval starts inherit this: no progress bars in the compared outputs (slamlab._progress).
os.environ["SLAMLAB_PROGRESS"] = "0"


def _execute_cell_input_with_history(self, cell_input, allow_stdin=None):
    """``RunningKernel.execute_cell_input`` with ``store_history=True`` (as in Jupyter)."""
    return self.kc.execute(cell_input, store_history=True, allow_stdin=allow_stdin, stop_on_error=False)


_nbval_kernel.RunningKernel.execute_cell_input = _execute_cell_input_with_history
