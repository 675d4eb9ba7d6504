"""Small frictions of the user's side (issue 27, item 7): what a missing extra says, and messages
without a NaN where a number belongs."""

from __future__ import annotations

import subprocess
import sys
import warnings

import numpy as np
import pytest

from tubefsi import AccuracyWarning
from tubefsi.numerics.quadrature import Integral, warn_unconverged


@pytest.mark.parametrize("statement, missing", [
    ("from tubefsi.testing import WallContract", "pytest"),
    ("import tubefsi.testing.fuzz", "hypothesis"),
])
def test_the_testing_suites_without_their_extra_say_how_to_install_it(statement, missing):
    code = f"import sys; sys.modules[{missing!r}] = None\n{statement}"       # as if not installed
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode != 0
    assert "ModuleNotFoundError" in run.stderr and "pip install '.[test]'" in run.stderr


def test_an_unconverged_integral_without_an_error_estimate_says_so_not_nan():
    result = Integral(value=np.array([1.0, 0.0]), error=np.array([np.nan, np.nan]),
                      converged=np.array([False, False]), panels=np.array([3, 3]))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        warn_unconverged("an integral", result)
    (message,) = [str(w.message) for w in caught if issubclass(w.category, AccuracyWarning)]
    assert "nan" not in message and "could not be estimated" in message


def test_the_thick_hgo_laws_slope_jumps_where_the_fibres_engage_as_the_docs_say():
    """docs/walls_beyond.md: at lambda_z = 1 the thick HGO law's slope (not only its curvature)
    jumps at lambda = 1, by 4 k1 cos^4(beta) (1 - (1 + t/a)^-2). Reference: that closed form,
    against one-sided differences of the tube law."""
    import math

    from tubefsi.registry import walls
    from tubefsi.walls.hgo import PRESETS

    media = PRESETS["rabbit-carotid-media"]
    wall, tb, h = walls["thick-hgo"](**media), 0.3, 1e-6
    above = (wall.pressure(1 + 2 * h, tb) - wall.pressure(1 + h, tb)) / h
    below = (wall.pressure(1 - h, tb) - wall.pressure(1 - 2 * h, tb)) / h
    jump = 4 * media["fibre_stiffness"] * math.cos(media["fibre_angle"]) ** 4 * (1 - (1 + tb) ** -2)
    assert abs((above - below) / jump - 1) < 1e-4


def test_a_misspelt_registry_name_suggests_the_intended_one():
    import tubefsi
    from tubefsi.registry import walls

    with pytest.raises(KeyError, match=r"did you mean 'thick-neo-hookean'\?"):
        walls["thick-neo-hookan"]
    tube = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
    with pytest.raises(tubefsi.InvalidParameterError, match=r"did you mean 'power-law'\?"):
        tubefsi.solve("power-lw", "rigid", tube, flow_rate=1e-9)


def test_tubefsi_list_describes_a_class_by_its_own_docstring_only():
    """A composed class without a docstring was described by its base's ("Thick-walled theory")."""
    import attrs

    from tubefsi.cli import _summary
    from tubefsi.walls import ThickWall
    from tubefsi.walls.neo_hookean import NeoHookean

    @attrs.frozen(kw_only=True)
    class Mine(ThickWall, NeoHookean):
        pass

    @attrs.frozen(kw_only=True)
    class Described(ThickWall, NeoHookean):
        """My wall, thick."""

    assert "no docstring" in _summary(Mine) and "Thick-walled" not in _summary(Mine)
    assert _summary(Described) == "My wall, thick"

