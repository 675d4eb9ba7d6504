"""Solution.to_dataframe() / to_xarray(): each point lands under the right labels (checked
against separate scalar solves of that point), with units; the optional packages are extras."""

import sys

import numpy as np
import pytest

import tubefsi
from tubefsi.registry import rheologies, walls

TUBE = tubefsi.Tube(radius=1e-4, thickness=3e-5, length=1e-2)
WALL = walls["thick-neo-hookean"](shear_modulus=2e3)
N = np.array([0.7, 0.8, 0.9])
Q = np.array([0.0, 3e-11, 1e-10, 2e-10])


def _curve():
    fluid = rheologies["power-law"](consistency=0.017, index=N)
    return tubefsi.solve(fluid, WALL, TUBE, flow_rate=Q[:, None])


def _point(q, n):
    return tubefsi.solve(rheologies["power-law"](consistency=0.017, index=float(n)), WALL, TUBE, flow_rate=float(q))


def test_xarray_names_a_dimension_per_axis_with_the_inputs_as_coordinates():
    pytest.importorskip("xarray")
    ds = _curve().to_xarray()
    assert ds.pressure_drop.dims == ("flow_rate", "index")
    np.testing.assert_array_equal(ds.flow_rate.values, Q)
    np.testing.assert_array_equal(ds["index"].values, N)
    assert ds.pressure_drop.attrs["units"] == "Pa" and ds.flow_rate.attrs["units"] == "m^3/s"
    for q in Q[1:]:
        for n in N:
            point = ds.sel(flow_rate=q, index=n)
            ref = _point(q, n)
            assert float(point.pressure_drop) == pytest.approx(ref.pressure_drop, rel=1e-12)
            assert float(point.inlet_radius) == pytest.approx(ref.inlet_radius, rel=1e-12)
    renamed = _curve().to_xarray(dims=("q", "n"))
    assert renamed.pressure_drop.dims == ("q", "n")
    with pytest.raises(tubefsi.InvalidParameterError, match="dims"):
        _curve().to_xarray(dims=("q",))


def test_xarray_writes_netcdf(tmp_path):
    xr = pytest.importorskip("xarray")
    path = tmp_path / "curve.nc"
    _curve().to_xarray().to_netcdf(path, engine="scipy")
    back = xr.open_dataset(path, engine="scipy")
    np.testing.assert_array_equal(back.pressure_drop.values, _curve().pressure_drop)
    back.close()


def test_dataframe_one_row_per_point():
    pytest.importorskip("pandas")
    frame = _curve().to_dataframe()
    assert list(frame.columns[:2]) == ["flow_rate", "index"] and len(frame) == Q.size * N.size
    assert frame.attrs["units"]["inlet_displacement"] == "m"
    for row in frame.itertuples():
        if row.flow_rate > 0:
            assert row.pressure_drop == pytest.approx(_point(row.flow_rate, row.index).pressure_drop, rel=1e-12)


def test_scalar_and_pressure_controlled_and_infeasible_points():
    pytest.importorskip("xarray")
    one = tubefsi.solve(rheologies["newtonian"](viscosity=1e-3), WALL, TUBE, flow_rate=1e-10)
    assert len(one.to_dataframe()) == 1 and one.to_xarray().pressure_drop.dims == ()
    limit = WALL.limit_pressure(TUBE.reduced_thickness)
    dp = np.array([10.0, 100.0, 2 * limit])
    sol = tubefsi.solve(rheologies["newtonian"](viscosity=1e-3), WALL, TUBE, pressure_drop=dp, on_infeasible="nan")
    ds = sol.to_xarray()
    assert ds.flow_rate.dims == ("pressure_drop",)
    np.testing.assert_array_equal(ds.feasible.values, [True, True, False])
    assert np.isnan(float(ds.flow_rate[-1]))


def test_a_missing_extra_says_how_to_install_it(monkeypatch):
    monkeypatch.setitem(sys.modules, "pandas", None)
    with pytest.raises(ImportError, match=r"tubefsi\[pandas\]"):
        _curve().to_dataframe()
