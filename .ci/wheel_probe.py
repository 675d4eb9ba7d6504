"""The wheel route's probe (.ci/run): one scene solved by the installed tubefsi, a plugin's wall
too. Without arguments it prints the pressure drop (run by the editable install: the reference);
given that value, it checks that it runs the installed wheel, not a source tree, with what the
wheel must ship, and that the wheel gives the same answer.
"""

import math
import sys
from importlib import metadata
from pathlib import Path

import tubefsi
from tubefsi.registry import rheologies, walls

tube = tubefsi.Tube(radius=100e-6, thickness=30e-6, length=1e-2)
sol = tubefsi.solve(rheologies["power-law"](consistency=0.017, index=0.7),
                    walls["thick-neo-hookean"](shear_modulus=2e3), tube, flow_rate=1e-9)
gent = tubefsi.solve(rheologies["newtonian"](viscosity=1e-3), walls["thick-gent"](shear_modulus=2e3, locking_parameter=3.0),
                     tube, flow_rate=1e-9)
if len(sys.argv) == 1:
    print(repr(sol.pressure_drop))
    sys.exit()

here = Path(tubefsi.__file__).parent
assert "site-packages" in here.parts, f"tubefsi imported from {here}, not from the installed wheel"
assert (here / "py.typed").is_file(), "py.typed is not in the wheel"
assert metadata.metadata("tubefsi")["License-Expression"] == "BSD-3-Clause"
assert walls.distribution("thick-gent") == "tubefsi-hyperelastic"
assert rheologies.distribution("carreau") == "tubefsi-rheologies"
assert math.isfinite(gent.pressure_drop) and gent.pressure_drop > 0, gent.pressure_drop
expected = float(sys.argv[1])
assert math.isclose(sol.pressure_drop, expected, rel_tol=1e-12), (sol.pressure_drop, expected)
print(f"wheel route: tubefsi {tubefsi.__version__} installed in {here.parent}; "
      f"pressure drop {sol.pressure_drop!r} Pa, as the editable install")
