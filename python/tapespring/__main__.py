"""``python -m tapespring``: the ``tapespring`` command (the console script's entry point,
:func:`tapespring.cli.main`)."""

import sys

from tapespring.cli import main

if __name__ == "__main__":
    sys.exit(main())
