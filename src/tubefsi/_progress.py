"""Progress bars for long work: tqdm (the optional extra ``tubefsi[progress]``), when asked.

``progress`` is False (no bar, the default), True (a bar; an ImportError naming the extra if
tqdm is missing) or ``"auto"`` (a bar only if tqdm is installed and standard error is a
terminal: what the command line uses).
"""

from __future__ import annotations

import sys

from .errors import InvalidParameterError

__all__ = ["bar"]


class _Silent:
    """The bar when none is shown."""

    def update(self, n=1):
        pass

    def close(self):
        pass


def bar(total: int, progress, desc: str, unit: str = "point"):
    """A progress bar over ``total`` units (``.update(n)``, ``.close()``), or a silent one."""
    if progress is None or progress is False:
        return _Silent()
    if progress is not True and progress != "auto":
        raise InvalidParameterError("progress", "{False, True, 'auto'}", progress)
    try:
        from tqdm import tqdm
    except ImportError:
        if progress == "auto":
            return _Silent()
        raise ImportError("progress=True needs tqdm: pip install 'tubefsi[progress]'") from None
    if progress == "auto" and not (hasattr(sys.stderr, "isatty") and sys.stderr.isatty()):
        return _Silent()
    # the finished bar stays (tqdm's default): a sweep that ends shows that it ended, at its total
    return tqdm(total=total, desc=desc, unit=unit, leave=True, file=sys.stderr)
