import os
import shutil
import tempfile

import numpy as np
import pytest


# the suite's own switches (pytest options, not environment variables), for the test modules to read
OPTIONS = {}


def pytest_addoption(parser):
    group = parser.getgroup("contactfem")
    group.addoption(
        "--require-browser",
        action="store_true",
        help="the course website's browser tests fail, not skip, where Chromium or the site extra is missing "
        "(.ci/run sets it)",
    )
    group.addoption(
        "--fuzz",
        choices=("quick", "long"),
        default="quick",
        help="the fuzz tests' profile: quick (about two minutes) or long (>= 500 cases, every scene)",
    )
    group.addoption(
        "--every-case",
        action="store_true",
        help="the tests that sample a study (the graded lectures, the sloping impact's discretisation rows) "
        "run every case",
    )


def pytest_configure(config):
    """The tests' own caches: $CONTACTFEM_CACHE (the inverse study's results) is a temporary
    folder for the session, so no test reads or writes the user's ~/.cache/contactfem (and a
    later command never answers from the tests' cache); and runs without error bars by default."""
    OPTIONS.update(
        require_browser=config.getoption("require_browser"),
        fuzz=config.getoption("fuzz"),
        every_case=config.getoption("every_case"),
    )
    config._contactfem_cache = tempfile.mkdtemp(prefix="contactfem-test-cache-")
    os.environ["CONTACTFEM_CACHE"] = config._contactfem_cache
    # every run of the suite (and of the command lines it starts) without error bars, which repeat a run at
    # coarser and finer levels: the tests of the bands ask for them (tests/test_uncertainty.py)
    os.environ["CONTACTFEM_ERROR_BARS"] = "off"


def pytest_unconfigure(config):
    folder = getattr(config, "_contactfem_cache", None)
    if folder:
        shutil.rmtree(folder, ignore_errors=True)


def _skip_reason(report):
    """The reason a skipped test report gives ('Chromium not installed ...')."""
    lr = report.longrepr
    text = lr[2] if isinstance(lr, tuple) and len(lr) == 3 else str(lr or "")
    return text.removeprefix("Skipped: ").strip()


def pytest_report_teststatus(report, config):
    """A skipped browser test (marked `site`) is counted under its reason, so that pytest's last
    line says why ("15 skipped (Chromium not installed (apt-get install -y chromium))"), not a
    bare "15 skipped"; .ci/run gives --require-browser, which makes it a failure."""
    if report.skipped and "site" in report.keywords and not hasattr(report, "wasxfail"):
        return f"skipped ({_skip_reason(report)})", "s", "SKIPPED"
    return None


class PointCloud:
    """A minimal body for contact tests: free nodes, two dofs each, no stiffness."""

    def __init__(self, X, name="cloud", dof_offset=0):
        self.name = name
        self.X = np.asarray(X, dtype=float)
        self.ndof = 2 * len(self.X)
        self.xdofs = np.arange(self.ndof).reshape(-1, 2)
        self.dof_offset = dof_offset


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


def assert_locate_matches_fd(master, x, atol=1e-7, atol2=1e-6, same_segment=True, h=1e-6):
    """A rigid master's projection at one point x: the first (dg_N, ds) and second
    (d2g_N, d2s) variations of ``locate`` against central differences."""
    x = np.array([x], dtype=float)
    k = master.locate(x, np.zeros(1), None)
    for i in range(2):
        d = np.zeros((1, 2))
        d[0, i] = h
        kp, km = master.locate(x + d, np.zeros(1), None), master.locate(x - d, np.zeros(1), None)
        if same_segment:
            assert kp["seg"][0] == km["seg"][0] == k["seg"][0]
        assert (kp["g_N"] - km["g_N"])[0] / (2 * h) == pytest.approx(k["dg_N"][0, i], abs=atol)
        assert (kp["s"] - km["s"])[0] / (2 * h) == pytest.approx(k["ds"][0, i], abs=atol)
        assert np.allclose((kp["dg_N"] - km["dg_N"])[0] / (2 * h), k["d2g_N"][0, i], atol=atol2)
        assert np.allclose((kp["ds"] - km["ds"])[0] / (2 * h), k["d2s"][0, i], atol=atol2)
