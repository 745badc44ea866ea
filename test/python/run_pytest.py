# This file is part of augocc. License: Apache-2.0.
"""CTest entry of the Python tests: pytest on this folder; exit 77 (CTest: skipped) when
pytest, numpy or the augocc module cannot be imported."""
import os
import sys

try:
    import numpy  # noqa: F401
    import pytest
except ImportError as e:
    print("SKIPPED: %s (install python3-pytest python3-numpy)" % e)
    sys.exit(77)
try:
    import augocc  # noqa: F401
except ImportError as e:
    print("SKIPPED: the augocc module is not importable (%s); PYTHONPATH=%s"
          % (e, os.environ.get("PYTHONPATH", "")))
    sys.exit(77)

sys.exit(pytest.main(["-q", "-p", "no:cacheprovider", os.path.dirname(os.path.abspath(__file__))]
                     + sys.argv[1:]))
