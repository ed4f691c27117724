"""Shared runs: each is simulated once per test session and reused (numba JIT cached)."""


import pytest

import trackbench as tb


@pytest.fixture(scope="session")
def paper_run():
    """paper_step, 0.5 s, default settings (reduced solver)."""
    return tb.simulate(tb.Scenario.paper())


@pytest.fixture(scope="session")
def paper_run_short():
    """paper_step to 0.25 s: the part of the run that is reproducible to 1e-4."""
    return tb.simulate(tb.Scenario.paper(duration=0.25))


@pytest.fixture(scope="session")
def continuous_run():
    """paper_step with contact.geometry = "continuous", no damping; outputs every 1e-5 s
    (the solver ends a step at every output time: consecutive samples are at most one
    step apart)."""
    return tb.simulate(tb.Scenario.paper(**{"contact.geometry": "continuous", "output_interval": 1e-5}))
