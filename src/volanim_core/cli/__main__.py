"""``python -m volanim_core.cli``: the volanim command line."""

import sys

from . import main

sys.exit(main())
