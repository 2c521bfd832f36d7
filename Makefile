# slamlab: set-up, tests and notebooks. `make lab` and `make test` are all a fresh machine needs.

PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

# -n 2 --dist loadfile: two pytest-xdist workers (both cores); each file, so each notebook's cells, stays in one
# --durations=30: the log ends with the 30 slowest tests (CI has a 20-minute goal)
PYTEST_ARGS := tests slamlab notebooks --doctest-modules \
	--nbval --nbval-current-env --nbval-sanitize-with notebooks/nbval_sanitize.cfg \
	-p no:cacheprovider -n 2 --dist loadfile --durations=30

.PHONY: venv data lab test test-latest reproducible notebooks report student autograde docs lint bench lock clean distclean

## venv: create .venv if missing and install slamlab[test] from constraints.txt and the instructor's grading package
## (grading/: the labs' references and accepted ranges, not part of the library; again only when those change)
venv: $(STAMP)

$(STAMP): pyproject.toml constraints.txt grading/pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --upgrade pip
	$(BIN)/python -m pip install -c constraints.txt -e '.[test]' -e ./grading
	touch $(STAMP)

## data: fetch every registered real data set that no data folder holds into the cache, verified (optional:
## notebooks fetch what they need on first use). SETS="carmen-radish-corrected oxford-affine" fetches only those;
## python -m slamlab.data list | verify | mirror DIR for the rest (README, "Data")
SETS ?=
data: venv
	$(BIN)/python -m slamlab.data fetch $(SETS)

## lab: start JupyterLab on notebooks/ (as root too, as the Jupyter Docker stacks do: containers and lab VMs)
LAB_ARGS ?=
ROOT_ARGS := $(if $(filter 0,$(shell id -u)),--allow-root,)
# Widget messages go to the kernel's main thread, not to subshells (JupyterLab >= 4.4 with ipykernel >= 7 handles
# them on threads of their own, so a widget's figure could be drawn while a cell draws another: matplotlib is not
# thread-safe, and its shared mathtext parser breaks, a ParseException): an overrides.json in the venv's lab settings.
LAB_OVERRIDES := $(VENV)/share/jupyter/lab/settings/overrides.json
lab: venv
	mkdir -p $(dir $(LAB_OVERRIDES))
	$(BIN)/python -c "import json, pathlib; p = pathlib.Path('$(LAB_OVERRIDES)'); d = json.loads(p.read_text()) if p.exists() else {}; d.setdefault('@jupyterlab/apputils-extension:kernels-settings', {})['commsOverSubshells'] = 'disabled'; p.write_text(json.dumps(d, indent=2))"
	$(BIN)/jupyter lab $(ROOT_ARGS) $(LAB_ARGS) notebooks/

## test: the whole suite in one pytest run: unit tests, doctests, every notebook under nbval
test: venv
	MPLBACKEND=Agg $(BIN)/python -m pytest $(PYTEST_ARGS)

## test-latest: dependency drift (not part of make test; run it before make lock): a temporary venv with the newest
## versions pyproject.toml allows (no constraints.txt), nbval over every notebook and lab there; prints each differing
## cell and the packages whose versions differ from the lock (tools/test_latest.py). LATEST_ARGS="--only 02 --jobs 2"
LATEST_ARGS ?=
test-latest:
	$(PYTHON) tools/test_latest.py $(LATEST_ARGS)

## reproducible: re-run every notebook and lab under another BLAS kernel, 1 thread, OpenCV 1 thread, no AVX-512,
## with OpenCV's and numpy's global RNGs moved first; compare every output with the stored one (VARIANT=alt|nosimd)
VARIANT ?= alt
reproducible: venv
	MPLBACKEND=Agg $(BIN)/python tools/check_reproducible.py --variant $(VARIANT)

## notebooks: re-execute every notebook in place (refreshes nbval's stored reference outputs)
notebooks: venv
	MPLBACKEND=Agg $(BIN)/python tools/run_notebooks.py

## report: run one notebook with other parameters into reports/, e.g. make report NB=01 PARAMS="CV_RUNS=10 SEED=7"
report: venv
	MPLBACKEND=Agg $(BIN)/python tools/report.py $(NB) $(PARAMS)

## student: the labs without their solutions (nbgrader generate_assignment) in build/student/
student: venv
	$(BIN)/python tools/labs.py student

## autograde: grade SUBMISSIONS=<folder of <student>/<NN_topic_lab>.ipynb>; writes build/course/grades.csv
## (JOBS=2: two groups of students graded at once)
JOBS ?= 1
autograde: venv
	$(BIN)/python tools/labs.py autograde $(SUBMISSIONS) --jobs $(JOBS)

## docs: the course site in build/site/ (open build/site/index.html): chapters with their stored outputs, the student
## labs and instructor guide, the API reference; offline, Sphinx warnings are errors (tools/build_site.py)
docs: venv
	$(BIN)/python tools/build_site.py

## lint: ruff
lint: venv
	$(BIN)/ruff check .

## bench: run every benchmarks/bench_*.py
bench: venv
	@set -e; for f in $(sort $(wildcard benchmarks/bench_*.py)); do \
		echo "== $$f"; MPLBACKEND=Agg $(BIN)/python $$f; \
	done

## lock: regenerate constraints.txt from a fresh temporary venv (then run `make test`)
lock:
	@set -e; tmp=$$(mktemp -d); trap 'rm -rf "$$tmp"' EXIT; \
	$(PYTHON) -m venv "$$tmp/venv"; \
	"$$tmp/venv/bin/python" -m pip install --upgrade pip; \
	"$$tmp/venv/bin/python" -m pip install -e '.[test]'; \
	"$$tmp/venv/bin/python" tools/freeze_lock.py > "$$tmp/constraints.txt"; \
	mv "$$tmp/constraints.txt" constraints.txt; \
	echo "constraints.txt updated; now run: make test"

## clean: remove caches and build leftovers (keeps .venv)
clean:
	rm -rf build dist *.egg-info .pytest_cache .ruff_cache
	find . -path ./$(VENV) -prune -o -type d \( -name __pycache__ -o -name .ipynb_checkpoints \) -print \
		| xargs rm -rf

## distclean: clean, and remove .venv too
distclean: clean
	rm -rf $(VENV)
