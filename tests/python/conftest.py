"""pytest configuration of the Python tests: the `slow` marker (the ctest entry test_python_slow,
label slow, runs them; test_python runs the rest)."""


def pytest_configure(config):
    config.addinivalue_line("markers", "slow: long end-to-end runs (ctest label slow)")
