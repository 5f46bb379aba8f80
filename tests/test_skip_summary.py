"""Without Chromium the browser tests skip, and pytest's last line says why (tests/conftest.py)."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent

SKIPPING = """
import pytest

pytestmark = [pytest.mark.site, pytest.mark.slow]


@pytest.mark.parametrize("k", range(3))
def test_page(k):
    pytest.skip("Chromium not installed (apt-get install -y chromium)")


def test_other():
    pass
"""


@pytest.mark.slow
def test_the_summary_line_names_why_browser_tests_skip(tmp_path):
    shutil.copy(TESTS / "conftest.py", tmp_path / "conftest.py")
    (tmp_path / "test_pages.py").write_text(SKIPPING)
    out = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-W", "ignore", str(tmp_path)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=120,
    )
    last = out.stdout.strip().splitlines()[-1]
    assert out.returncode == 0, out.stdout + out.stderr
    assert "1 passed" in last and "3 skipped (Chromium not installed (apt-get install -y chromium))" in last, last
