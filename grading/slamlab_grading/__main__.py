"""``python -m slamlab_grading feedback [NN ...]``: write the student's feedback files (``slamlab/lab/feedback/NN.json``),
of every lab or of the labs named."""

import sys

from . import TASK_MODULES, export_feedback

if __name__ == "__main__":
    if sys.argv[1:2] != ["feedback"] or not set(sys.argv[2:]) <= set(TASK_MODULES):
        sys.exit(f"usage: python -m slamlab_grading feedback [NN ...] (NN one of {' '.join(sorted(TASK_MODULES))})")
    for path in export_feedback(chapters=sys.argv[2:] or None):
        print(path)
