"""``python -m lugre``: the same as the ``lugre`` command."""

import sys

from .cli import main

sys.exit(main())
