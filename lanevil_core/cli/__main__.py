"""``python -m lanevil_core.cli``: the ``lanevil`` command."""

import sys

from . import main

sys.exit(main())
