# The two commands: `make book` (execute every chapter, build the HTML book) and
# `make test` (unit tests + nbval over every notebook). Both create .venv from
# environment.txt on first use; PYTHON picks the interpreter for that venv.
PYTHON ?= python3.11
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: book student student-notebooks handout grade test unit nbval lab lab-instructor serve benchmark lint clean

$(STAMP): environment.txt pyproject.toml
	@command -v $(PYTHON) >/dev/null 2>&1 || { echo "error: $(PYTHON) not found; run 'make PYTHON=/path/to/python3.11 ...'" >&2; exit 1; }
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -r environment.txt
	$(BIN)/python -m pip install --quiet --no-deps --no-build-isolation -e .
	$(BIN)/python scripts/compile_loops.py
	@touch $(STAMP)

book: $(STAMP)
	rm -rf book/chapters _build/html
	mkdir -p book/chapters
	cp notebooks/*.ipynb book/chapters/
	MPLBACKEND=module://matplotlib_inline.backend_inline $(BIN)/sphinx-build -W --keep-going -q -b html book _build/html
	@echo "Book built: $(CURDIR)/_build/html/index.html"

# The student edition (otter-grader: answer cells, public tests, no solutions), the autograders,
# the solved notebooks and the points; then its book, from the stored outputs
student-notebooks: $(STAMP)
	rm -rf _build/student/notebooks _build/student/autograder _build/student/solved
	$(BIN)/python scripts/student_edition.py _build/student

student: student-notebooks
	rm -rf book/chapters _build/student/html
	mkdir -p book/chapters
	cp _build/student/notebooks/*.ipynb book/chapters/
	MPLBACKEND=module://matplotlib_inline.backend_inline $(BIN)/sphinx-build -W --keep-going -q -b html \
		-D nb_execution_mode=off book _build/student/html
	@echo "Student notebooks: $(CURDIR)/_build/student/notebooks; book: $(CURDIR)/_build/student/html/index.html"

# What to hand to students: quadlib, the data and the student edition, without the chapters' solutions
handout: student-notebooks
	rm -rf _build/handout
	mkdir -p _build/handout/benchmarks
	cp -r quadlib data pyproject.toml environment.txt LICENSE _build/handout/
	cp -r benchmarks/results _build/handout/benchmarks/
	cp -r _build/student/notebooks _build/handout/notebooks
	find _build/handout -name __pycache__ -prune -exec rm -rf {} +
	printf '%s\n' "# State estimation for drones: the student edition" "" \
		"python3.11 -m venv .venv && .venv/bin/pip install -r environment.txt && .venv/bin/pip install --no-deps -e ." \
		".venv/bin/jupyter lab notebooks" "" \
		"Each exercise ends with grader.check(\"qN\"): it says whether your answer is set. Hand in the notebook." \
		> _build/handout/README.md
	@echo "Hand-out: $(CURDIR)/_build/handout (zip it, or put it in a repository of its own)"

# make grade SUBMISSIONS=folder [CELL_TIMEOUT=120] [SUBMISSION_TIMEOUT=1200]: grade every submitted
# notebook with the instructor's tests, write folder/scores.csv
CELL_TIMEOUT ?= 120
SUBMISSION_TIMEOUT ?= 1200
grade: $(STAMP)
	@test -n "$(SUBMISSIONS)" || { echo "usage: make grade SUBMISSIONS=folder-of-notebooks" >&2; exit 1; }
	@test -d _build/student/autograder || $(MAKE) student-notebooks
	$(BIN)/python scripts/grade.py $(SUBMISSIONS) --cell-timeout $(CELL_TIMEOUT) --submission-timeout $(SUBMISSION_TIMEOUT)

NBVAL := --nbval --nbval-sanitize-with notebooks/nbval_sanitize.cfg --nbval-cell-timeout=300 -p no:cacheprovider

# One pytest session: unit tests and every notebook's stored outputs (nbval strict), on every core
# (pytest-xdist; --dist loadscope keeps each notebook's cells, which share one kernel, on one worker).
test: $(STAMP)
	$(BIN)/python -m pytest -n auto --dist loadscope tests notebooks $(NBVAL)

unit: $(STAMP)
	$(BIN)/python -m pytest tests

nbval: $(STAMP)
	$(BIN)/python -m pytest notebooks $(NBVAL)

# make lab ARGS="--allow-root --no-browser --port 8890": options for JupyterLab.
# Students open the student edition (written first if needed); instructors the chapters with solutions.
ARGS ?=
lab: $(STAMP)
	@test -d _build/student/notebooks || $(MAKE) student-notebooks
	$(BIN)/jupyter lab _build/student/notebooks $(ARGS)

lab-instructor: $(STAMP)
	$(BIN)/jupyter lab notebooks $(ARGS)

# The built book over http://127.0.0.1:8000 (its search needs a server; file:// pages cannot load the index)
PORT ?= 8000
serve:
	@test -d _build/html || { echo "no book yet: run 'make book' first" >&2; exit 1; }
	$(BIN)/python -m http.server $(PORT) --bind 127.0.0.1 -d _build/html

benchmark: $(STAMP)
	$(BIN)/python benchmarks/run_all.py
	$(BIN)/python benchmarks/wrapper_overhead.py
	$(BIN)/python benchmarks/quad3d_filters.py
	$(BIN)/python benchmarks/attitude_filters.py
	$(BIN)/python benchmarks/fixedwing_filters.py
	$(BIN)/python benchmarks/estimator_cost.py
	$(BIN)/python benchmarks/orientation_cost.py
	$(BIN)/python benchmarks/orientation_ablation.py
	$(BIN)/python benchmarks/fixedwing_divergence.py
	$(BIN)/python benchmarks/faults.py
	$(BIN)/python benchmarks/broad_orientation.py
	$(BIN)/python benchmarks/montecarlo_batch.py
	$(BIN)/python benchmarks/icp_basin.py
	$(BIN)/python benchmarks/particle_filter.py

lint: $(STAMP)
	$(BIN)/ruff check quadlib tests benchmarks scripts book/conf.py conftest.py

clean:
	rm -rf _build book/chapters .jupyter_cache
