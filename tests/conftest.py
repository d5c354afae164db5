"""Shared fixtures: paths to the repository's sample twin and the shared instrument files,
and the sample patch's flow factors (computed once per session)."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "meshes" / "sample"
SHARED_TOPOGRAPHIES = ROOT.parent / "shared" / "topographies"


@pytest.fixture(autouse=True)
def machine_speed(monkeypatch):
    """Every test sees the calibration machine's speed (``FEM_TWIN_SLOWDOWN=1``, no probe):
    no outcome depends on how fast this machine measures itself (issue 64 item 0); the
    probe's own test removes it."""
    monkeypatch.setenv("FEM_TWIN_SLOWDOWN", "1")


@pytest.fixture
def shared_topographies():
    """The measured instrument files beside the project (absent in a user's fresh clone)."""
    if not SHARED_TOPOGRAPHIES.is_dir():
        pytest.skip(f"shared instrument files not found at {SHARED_TOPOGRAPHIES}")
    return SHARED_TOPOGRAPHIES


@pytest.fixture(scope="session")
def factors():
    """Flow factors of sample patch pair 1 (:func:`sample_cases.sample_factors`)."""
    from sample_cases import sample_factors
    return sample_factors()
