"""Shared by every pytest run from the project root (unit tests and nbval): no progress bars,
so that the notebooks' kernels, which inherit this environment, write the stored outputs; and the
order in which pytest-xdist hands tests to its workers."""

from quadlib.progress import switch_off

switch_off()

MUTATION_TEST = "tests/teaching/test_grading.py::test_every_blank_and_every_wrong_answer_listed_is_rejected["


def pytest_xdist_make_scheduler(config, log):
    """``--dist loadscope`` (a notebook's cells share one kernel, so they stay on one worker), except
    that each chapter's mutation run, which starts a kernel of its own, is a unit of its own: as one
    module they were one worker's serial share of several minutes."""
    from xdist.scheduler import LoadScopeScheduling

    class ChapterScopes(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return nodeid if nodeid.startswith(MUTATION_TEST) else super()._split_scope(nodeid)

    return ChapterScopes(config, log) if config.getoption("dist") == "loadscope" else None
