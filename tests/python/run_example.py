"""ctest entry of an example under examples/python/: skips (exit 77) without matplotlib or the
built package, else runs SCRIPT with the remaining arguments."""
import importlib.util
import runpy
import sys

for mod in ("numpy", "matplotlib", "animkit"):
    if importlib.util.find_spec(mod) is None:
        print(f"SKIP: {mod} is not importable")
        sys.exit(77)
sys.argv = sys.argv[1:]
runpy.run_path(sys.argv[0], run_name="__main__")
