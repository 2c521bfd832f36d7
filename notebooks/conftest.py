"""pytest set-up for the notebooks run under nbval (``make test``).

nbval (0.10, 0.11) sends each cell with ``store_history=False``. IPython decides
whether a trailing ``;`` silences a cell's result by reading the last *history*
entry, so under nbval ``sl.plotting.plot_slam_scheme();`` returns its ``Axes`` repr,
while Jupyter and nbclient (which wrote the stored outputs) show nothing: every
plotting cell would differ from its reference. Known and open upstream:
computationalmodelling/nbval#194 and ipython/ipython#14162. Until they are fixed,
nbval runs cells here the way Jupyter does, with history.

A kernel that dies before it answers ``kernel_info`` is started again, up to
``KERNEL_START_TRIES`` times in all: on 2026-11-27 one fresh-clone CI run lost
notebook 09's kernel that way (every cell errored at setup, "Kernel died before
replying to kernel_info"), and the same notebook then passed twice in a row. nbval
sends the kernel's stderr to /dev/null, so the cause was not seen. No notebook code
has run when this happens, so starting again hides no notebook's failure.
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


#: Kernel starts nbval may try per notebook (see the module docstring).
KERNEL_START_TRIES = 3
_start_new_kernel = _nbval_kernel.start_new_kernel


def _start_new_kernel_again_if_it_died(*args, **kwargs):
    """nbval's ``start_new_kernel``, started again when the kernel dies before it is ready."""
    for attempt in range(1, KERNEL_START_TRIES + 1):
        try:
            return _start_new_kernel(*args, **kwargs)
        except RuntimeError as err:  # "Kernel died before replying to kernel_info", or a start-up timeout
            if attempt == KERNEL_START_TRIES:
                raise
            print(f"nbval: the kernel did not start ({err}); starting it again ({attempt + 1}/{KERNEL_START_TRIES})")


_nbval_kernel.start_new_kernel = _start_new_kernel_again_if_it_died
