"""``python -m tubefsi.testing.fuzz``: the campaign (:func:`tubefsi.testing.fuzz.main`)."""

import sys

from . import main

sys.exit(main())
