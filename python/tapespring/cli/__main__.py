"""``python -m tapespring.cli``: the ``tapespring`` command."""

import sys

from . import main

sys.exit(main())
