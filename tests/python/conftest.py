"""pytest suites of the Python package (ctest python.*; docs/guide/python.md).

Run as ctest does:
    PYTHONPATH=build/python /usr/bin/python3 -m pytest tests/python/test_generator.py \\
        --portalsim build/portalsim
A skipped test fails the run (as .ci/run fails a skipped GoogleTest), and pytest's exit 5 (no
tests collected) is non-zero, so ctest fails it too.
"""
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
_skipped = []


def pytest_addoption(parser):
    parser.addoption("--portalsim", required=True, help="the portalsim binary (generate's rows to compare)")


@pytest.fixture(scope="session")
def portalsim_bin(request):
    return request.config.getoption("--portalsim")


@pytest.fixture(scope="session")
def root():
    return ROOT


def pytest_runtest_logreport(report):
    if report.skipped:
        _skipped.append(report.nodeid)


def pytest_sessionfinish(session, exitstatus):
    if _skipped and session.exitstatus == 0:
        print(f"\nskipped tests fail this suite: {', '.join(_skipped)}")
        session.exitstatus = 1
