"""The stored BROAD table (benchmarks/results/broad_orientation.csv, shown in chapter 16) is what the
code computes: the rows of the fast estimators are recomputed here from the trials."""

import csv
from pathlib import Path

import pytest

from quadlib.analysis import broad_errors
from quadlib.analysis.orientation_table import estimator_names, orientation_estimate
from quadlib.data import broad_trial_names, load_broad_trial
from quadlib.perception import corner_trials

RESULTS = Path(__file__).resolve().parents[1] / "benchmarks" / "results" / "broad_orientation.csv"


def _table():
    with RESULTS.open(newline="") as f:
        return {(row["trial"], row["estimator"]): row for row in csv.DictReader(f)}


def test_the_table_has_every_estimator_on_every_trial():
    table = _table()
    assert set(table) == {(t, e) for t in broad_trial_names() for e in estimator_names()}


@pytest.mark.parametrize("trial", broad_trial_names())
def test_the_fast_rows_are_reproduced(trial):
    table, data = _table(), load_broad_trial(trial)
    for name in ("VQF", "offline VQF", "BasicVQF"):
        errors = broad_errors(orientation_estimate(name, data.log), data.q_nb, data.movement)
        for column, value in errors.items():
            assert float(table[trial, name][column]) == pytest.approx(value, abs=1e-3), (name, column)


PARTICLES = Path(__file__).resolve().parents[1] / "benchmarks" / "results" / "particle_filter.csv"


def test_the_particle_filter_table_is_reproduced_for_its_cheapest_row():
    """Chapter 20 shows benchmarks/results/particle_filter.csv; its first row (50 particles) is
    recomputed here: the share of runs that found the pose and their median error."""
    with PARTICLES.open(newline="") as f:
        row = next(csv.DictReader(f))
    share, error, _ = corner_trials(int(row["particles"]), int(row["runs"]), scheme=row["scheme"],
                                    sigma_m=float(row["sigma_m"]))
    assert share == pytest.approx(float(row["found"]), abs=1e-9)
    assert error == pytest.approx(float(row["median_error_m"]), abs=1e-3)


ATTITUDE = Path(__file__).resolve().parents[1] / "benchmarks" / "results" / "attitude_filters.csv"


def test_the_fig_5_2_table_is_reproduced_for_its_cheapest_filter():
    """benchmarks/results/attitude_filters.csv (two minutes of tumbling per entry, the tables chapter 13
    computes): the TQKF's entry at k = 1 with the thesis's noise is recomputed here."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("attitude_filters", ATTITUDE.parents[1] / "attitude_filters.py")
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    with ATTITUDE.open(newline="") as f:
        rows = {(r["noise"], int(r["k"]), r["filter"]): r for r in csv.DictReader(f)}
    assert len(rows) == 2 * 5 * 5
    row = rows["thesis", 1, "TQKF"]
    value = bench.fig_5_2_entry("TQKF", "thesis", 1, seconds=float(row["seconds"]), seed=int(row["seed"]))
    assert value == pytest.approx(float(row["mse_deg2"]), rel=1e-4)
