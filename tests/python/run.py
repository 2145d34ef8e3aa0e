"""ctest entry of the Python tests: skips (exit 77) when pytest, numpy or the built package are
missing, else runs pytest on this folder: the fast tests, or with --slow the ones marked slow
(the Dask cluster test). Other arguments are passed on to pytest."""
import os
import sys

try:
    import numpy  # noqa: F401
    import pytest
except ImportError as e:
    print(f"SKIP: {e.name} is not installed (Debian python3-numpy python3-pytest)")
    sys.exit(77)
try:
    import animkit  # noqa: F401
except ImportError as e:
    print(f"SKIP: the animkit package is not built or not on PYTHONPATH ({e})")
    sys.exit(77)
here = os.path.dirname(os.path.abspath(__file__))
args = sys.argv[1:]
select = "slow" if "--slow" in args else "not slow"
args = [a for a in args if a != "--slow"]
sys.exit(pytest.main(["-q", "-p", "no:cacheprovider", "-m", select, here, *args]))
