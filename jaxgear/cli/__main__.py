"""``python -m jaxgear.cli``: the ``jaxgear`` command."""

import sys

from .main import main

sys.exit(main())
