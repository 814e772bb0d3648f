"""The stored BROAD table (benchmarks/results/broad_orientation.csv, shown in chapter 13) is what the
code computes: the rows of the fast estimators are recomputed here from the trials."""

import csv
from pathlib import Path

import pytest

from quadlib.analysis import broad_errors
from quadlib.analysis.orientation_table import estimator_names, orientation_estimate
from quadlib.data import broad_trial_names, load_broad_trial

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
