"""Data sets shipped with tubefsi (``src/tubefsi/data/README.md`` gives their sources and
licenses; ``docs/network.md``, "Files").

* :func:`adan56`: the 77-vessel ADAN56 arterial network (Blanco et al. 2015; the openBF model
  hub, Apache-2.0), as openBF's model table.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path


__all__ = ["adan56"]


def adan56() -> Path:
    r"""The path of the ADAN56 arterial network's table (CSV): 77 vessels between 78 nodes,
    the aortic root at node 1, 31 terminal vessels with a three-element Windkessel (R1, R2, C),
    39 tapered vessels (``Rp != Rd``);
    ``tubefsi.read_network_table(adan56(), rheology=..., wall=...)`` makes the network.

    Blanco PJ, Watanabe SM, Passos MA, Lemos PA, Feijóo RA, "An anatomically detailed arterial
    network model for one-dimensional computational hemodynamics", *IEEE Trans. Biomed. Eng.*
    62(2):736–753, 2015; the table of the openBF model hub (Apache License 2.0), unmodified.
    """
    return Path(str(resources.files("tubefsi") / "data" / "adan56.csv"))
