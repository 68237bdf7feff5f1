"""``python -m cosim``: the same as the ``cosim`` command."""
import sys

from cosim.cli import main

sys.exit(main())
