"""What the tests share beyond fixtures (those are in tests/conftest.py): where the repository's
folders are, camera rays (``rays``), volume files (``volume_files``), the X11 session of window
tests (``x11``), a Ray cluster (``ray_cluster``) and wheels (``wheel_tools``). Tests import it as
``helpers``: pytest puts tests/ on sys.path for the root conftest, and the fuzzing and benchmark
scripts put it there themselves."""

from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
TESTS = REPO / "tests"
EXAMPLES = REPO / "examples"
NOTEBOOKS = REPO / "notebooks"
