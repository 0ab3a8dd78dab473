"""``python -m tests.fuzz [--sample N --seed S] [--areas ...] [--jobs J] [--json out]``: see :mod:`tests.fuzz`."""

import sys

from tests.fuzz._runner import main

sys.exit(main())
