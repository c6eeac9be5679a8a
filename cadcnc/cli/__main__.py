"""``python -m cadcnc.cli``: the same as the ``cadcnc`` console script."""

import sys

from . import main

sys.exit(main())
