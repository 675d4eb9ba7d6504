"""Networks from and to files (tubefsi.network_io, docs/network.md "Files"): the vessel table
form of openBF, the ADAN56 data set, VTK polylines; and the network's pictures and tables.

References: the ADAN56 file itself, read with the csv module; a Y of rigid tubes with
resistance outlets against Poiseuille's resistances in series and parallel, in mpmath; the
empirical thickness against its formula in centimetres, in mpmath.
"""

from __future__ import annotations

import base64
import csv
import xml.etree.ElementTree as ET
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tubefsi
from tubefsi import InvalidParameterError, datasets, network_io
from tubefsi.registry import rheologies, walls

NEWTONIAN = rheologies["newtonian"](viscosity=3.5e-3)


def _adan56_rows():
    with open(datasets.adan56(), newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))
    return rows[0], rows[1:]


def test_adan56_ships_77_vessels_78_nodes_and_its_terminals():
    header, rows = _adan56_rows()
    assert [h.strip() for h in header[:13]] == ["Name", "sn", "tn", "wkn", "l(m)", "M", "Rp(m)", "Rd(m)", "E(Pa)",
                                                "Pext", "R1", "R2", "C"]
    net = tubefsi.read_network_table(datasets.adan56(), rheology=NEWTONIAN, taper="mean")
    assert len(net.tube_names) == 77 == len(rows)
    assert len(net.nodes) == 78
    assert net.tube_names == [r[0] for r in rows]
    terminals = {int(r[2]): float(r[10]) + float(r[11]) for r in rows if float(r[10]) > 0}
    assert len(terminals) == 31
    assert net._resistance == {node: (r, 0.0) for node, r in terminals.items()}
    # the tree: every node but the root (1) is the target of exactly one vessel
    assert sorted(int(r[2]) for r in rows) == list(range(2, 79))


def test_adan56_with_linear_tapers():
    net = tubefsi.read_network_table(datasets.adan56(), rheology=NEWTONIAN)
    assert len(net.tube_names) == 77


def test_the_data_file_is_package_data():
    import tomllib

    config = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text(encoding="utf-8"))
    assert "data/*.csv" in config["tool"]["setuptools"]["package-data"]["tubefsi"]
    readme = datasets.adan56().parent / "README.md"
    assert "Apache License, Version 2.0" in readme.read_text(encoding="utf-8")


def test_empirical_thickness_against_the_formula_in_centimetres():
    # h = R (a exp(b R) + c exp(d R)) with R in cm, b = -5.053 /cm, d = -0.1114 /cm (Avolio 1980)
    radii = np.array([1e-4, 1.3e-3, 4.5e-3, 1.595e-2])
    for r, h in zip(radii, network_io.empirical_thickness(radii)):
        r_cm = mp.mpf(float(r)) * 100
        expected = r_cm * (mp.mpf("0.2802") * mp.exp(mp.mpf("-5.053") * r_cm)
                           + mp.mpf("0.1324") * mp.exp(mp.mpf("-0.1114") * r_cm)) / 100
        assert h == pytest.approx(float(expected), rel=1e-14)


def test_table_round_trip(tmp_path):
    net = tubefsi.read_network_table(datasets.adan56(), rheology=NEWTONIAN, taper="mean")
    path = network_io.write_network_table(net, tmp_path / "adan.csv", comment="ADAN56, mean radii")
    again = tubefsi.read_network_table(path, rheology=NEWTONIAN)
    assert network_io.network_table(again) == network_io.network_table(net)
    # the thickness follows openBF's rule, so the table has no h column; the file's own columns
    columns = network_io.network_table(net)
    assert "h(m)" not in columns
    _, rows = _adan56_rows()
    assert columns["Name"] == [r[0] for r in rows]
    assert columns["l(m)"] == [float(r[4]) for r in rows]
    assert columns["E(Pa)"] == [float(r[8]) for r in rows]
    assert columns["Rp(m)"] == [0.5 * (float(r[6]) + float(r[7])) for r in rows]
    assert [a + b for a, b in zip(columns["R1"], columns["R2"])] == [float(r[10]) + float(r[11]) for r in rows]


def test_table_round_trip_with_thickness_and_external_pressure(tmp_path):
    net = tubefsi.Network(rheology=NEWTONIAN)
    wall = walls["thin-linear"](youngs_modulus=4e5, poisson_ratio=0.5)
    net.add_tube(1, 2, wall, tubefsi.Tube(radius=2e-3, thickness=3e-4, length=0.1), name="a", external_pressure=50.0)
    net.add_tube(2, 3, wall, tubefsi.Tube(radius=1e-3, thickness=2e-4, length=0.05), name="b")
    net.set_resistance(3, 2e9)
    columns = network_io.network_table(net)
    assert columns["h(m)"] == [3e-4, 2e-4] and columns["Pext"] == [50.0, 0.0] and columns["R1"] == [0.0, 2e9]
    path = network_io.write_network_table(net, tmp_path / "two.csv")
    assert network_io.network_table(tubefsi.read_network_table(path, rheology=NEWTONIAN)) == columns


def test_tapered_table_round_trip(tmp_path):
    net = tubefsi.read_network_table(datasets.adan56(), rheology=NEWTONIAN)
    path = network_io.write_network_table(net, tmp_path / "adan.csv")
    _, rows = _adan56_rows()
    columns = network_io.network_table(tubefsi.read_network_table(path, rheology=NEWTONIAN))
    assert columns["Rd(m)"] == [float(r[7]) for r in rows]


def test_a_tapered_rigid_vessel_against_poiseuille(tmp_path):
    # a linear taper a(z) from a_p to a_d: R = (8 mu / pi) int_0^L dz / a^4
    #                                          = 8 mu L (a_p^2 + a_p a_d + a_d^2) / (3 pi a_p^3 a_d^3)
    path = tmp_path / "taper.csv"
    path.write_text("Name,sn,tn,l(m),Rp(m),Rd(m),R1\ncone,1,2,0.2,0.004,0.002,0\n", encoding="utf-8")
    net = tubefsi.read_network_table(path, rheology=NEWTONIAN, wall="rigid")
    net.set_pressure(1, 500.0).set_pressure(2, 0.0)
    mu, length, ap, ad = mp.mpf("3.5e-3"), mp.mpf("0.2"), mp.mpf("0.004"), mp.mpf("0.002")
    resistance = 8 * mu * length * (ap**2 + ap * ad + ad**2) / (3 * mp.pi * ap**3 * ad**3)
    assert net.solve().flow_rate["cone"] == pytest.approx(float(500 / resistance), rel=1e-10)


def test_a_tapered_row_is_a_linear_taper():
    # the Tube a tapered row becomes (a network takes it once tapered edges land)
    table = network_io._Table("t.csv", ["Name", "sn", "tn", "l(m)", "Rp(m)", "Rd(m)", "E(Pa)"],
                              [["x", "1", "2", "0.1", "0.002", "0.001", "4e5"]], ["line 2"])
    assert table.names("sn") == [1]
    thickness = network_io._ThicknessOf(network_io.empirical_thickness, 2e-3, 1e-3, 0.1)
    z = np.array([0.0, 0.05, 0.1])
    np.testing.assert_allclose(thickness(z), network_io.empirical_thickness([2e-3, 1.5e-3, 1e-3]), rtol=1e-15)


def _y_table(path):
    path.write_text("# a Y of rigid tubes with two resistance outlets\n"
                    "Name, sn, tn, l(m), Rp(m), Rd(m), R1, R2,\n"
                    "trunk, 1, 2, 0.2, 0.004, 0.004, 0., 0.,\n"
                    "left, 2, 3, 0.15, 0.003, 0.003, 1e8, 3e8,\n"
                    "right, 2, 4, 0.1, 0.002, 0.002, 2e8, 5e8,\n", encoding="utf-8")
    return path


def test_a_y_of_rigid_tubes_against_poiseuille_in_mpmath(tmp_path):
    mp.mp.dps = 30
    mu, q_in, p_d = mp.mpf("3.5e-3"), mp.mpf("1e-5"), mp.mpf(1000)

    def poiseuille(length, radius):
        return 8 * mu * mp.mpf(length) / (mp.pi * mp.mpf(radius) ** 4)

    left = poiseuille("0.15", "0.003") + mp.mpf("4e8")
    right = poiseuille("0.1", "0.002") + mp.mpf("7e8")
    p2 = p_d + q_in / (1 / left + 1 / right)
    p1 = p2 + q_in * poiseuille("0.2", "0.004")
    net = tubefsi.read_network_table(_y_table(tmp_path / "y.csv"), rheology=NEWTONIAN, wall="rigid",
                                     distal_pressure=1000.0)
    net.set_inflow(1, 1e-5)
    result = net.solve()
    assert result.pressure[1] == pytest.approx(float(p1), rel=1e-11)
    assert result.pressure[2] == pytest.approx(float(p2), rel=1e-11)
    assert result.flow_rate["left"] == pytest.approx(float((p2 - p_d) / left), rel=1e-10)


def test_a_dataframe_reads_as_the_file(tmp_path):
    pd = pytest.importorskip("pandas")
    path = _y_table(tmp_path / "y.csv")
    frame = pd.read_csv(path, comment="#", skipinitialspace=True).dropna(axis=1, how="all")
    with pytest.raises(InvalidParameterError, match="youngs_modulus"):
        network_io.network_table(tubefsi.read_network_table(path, rheology=NEWTONIAN, wall="rigid"))
    b = tubefsi.read_network_table(path, rheology=NEWTONIAN, wall=lambda E, h, R: walls["thin-linear"](
        youngs_modulus=1e6, poisson_ratio=0.5))
    c = tubefsi.read_network_table(frame, rheology=NEWTONIAN, wall=lambda E, h, R: walls["thin-linear"](
        youngs_modulus=1e6, poisson_ratio=0.5))
    assert network_io.network_table(b) == network_io.network_table(c)
    assert network_io.network_table(c)["Name"] == ["trunk", "left", "right"]


BAD = [
    ("Name, sn, tn, l(m), Rp(m), E(Pa)\nx, 1, 2, 0.1, oops, 4e5\n", "bad.csv, line 2, column 'Rp(m)'"),
    ("Name, sn, tn, l(m), Rp(m), E(Pa)\nx, 1, 2, 0.1, 0.001, 4e5\ny, 2, 3, -0.1, 0.001, 4e5\n",
     "bad.csv, line 3, column 'l(m)'"),
    ("Name, sn, tn, l(cm), Rp(m), E(Pa)\nx, 1, 2, 10, 0.001, 4e5\n", "bad.csv, column 'l(cm)'"),
    ("Name, sn, tn, l(m), Rp(m), E(Pa), colour\nx, 1, 2, 0.1, 0.001, 4e5, red\n", "bad.csv, column 'colour'"),
    ("Name, sn, l(m), Rp(m), E(Pa)\nx, 1, 0.1, 0.001, 4e5\n", "bad.csv must be a table with a column 'tn'"),
    ("Name, sn, tn, l(m), Rp(m), E(Pa)\nx, 1, 1, 0.1, 0.001, 4e5\n", "bad.csv, line 2, column 'tn'"),
    ("Name, sn, tn, l(m), Rp(m), E(Pa)\nx, 1, 2, 0.1, 0.001, 4e5\n\n# c\nx, 2, 3, 0.1, 0.001, 4e5\n",
     "bad.csv, line 5, column 'Name'"),
    ("Name, sn, tn, l(m), Rp(m), E(Pa)\nx, 1, 2, 0.1, 0.001, 4e5, 7\n", "bad.csv, line 2"),
    ("Name, sn, tn, l(m), Rp(m)\nx, 1, 2, 0.1, 0.001\n", "E(Pa)"),
    ("Name, sn, tn, l(m), Rp(m), E(Pa), R1\nx, 1, 2, 0.1, 0.001, 4e5, -5\n", "bad.csv, line 2, column 'R1'"),
    ("", "bad.csv"),
    ("Name, sn, tn, l(m), Rp(m), E(Pa), h(m), hd(m)\nx, 1, 2, 0.1, 0.001, 4e5, , 1e-4\n", "bad.csv, line 2, column 'hd(m)'"),
    ("Name, sn, tn, l(m), Rp(m), E(Pa), hd(m)\nx, 1, 2, 0.1, 0.001, 4e5, 1e-4\n", "bad.csv must be a column h(m)"),
    ("Name, sn, tn, l(m), Rp(m), E(Pa), R1, Pd(Pa)\nx, 1, 2, 0.1, 0.001, 4e5, 0, 5\n", "bad.csv, line 2, column 'Pd(Pa)'"),
]


@pytest.mark.parametrize("text, where", BAD)
def test_a_malformed_table_names_file_line_and_column(tmp_path, text, where):
    path = tmp_path / "bad.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(InvalidParameterError) as err:
        tubefsi.read_network_table(path, rheology=NEWTONIAN)
    assert where in str(err.value)


def test_bad_options():
    with pytest.raises(InvalidParameterError, match="taper"):
        tubefsi.read_network_table(datasets.adan56(), rheology=NEWTONIAN, taper="cubic")
    with pytest.raises(InvalidParameterError, match="wall"):
        tubefsi.read_network_table(datasets.adan56(), rheology=NEWTONIAN, wall=3.0)
    with pytest.raises(InvalidParameterError, match="source"):
        tubefsi.read_network_table(42, rheology=NEWTONIAN)


def _solved_y():
    net = tubefsi.Network(rheology=NEWTONIAN)
    wall = walls["thin-linear"](youngs_modulus=4e5, poisson_ratio=0.5)
    net.add_tube("in", "j", wall, tubefsi.Tube(radius=2e-3, thickness=3e-4, length=0.1))
    net.add_tube("j", "a", wall, tubefsi.Tube(radius=1e-3, thickness=2e-4, length=0.05), external_pressure=10.0)
    net.add_tube("j", "b", wall, tubefsi.Tube(radius=1.2e-3, thickness=2e-4, length=0.06))
    net.set_inflow("in", 1e-6).set_pressure("a", 100.0).set_resistance("b", 1e9, distal_pressure=20.0)
    return net, net.solve()


def test_vtp_round_trip(tmp_path):
    net, result = _solved_y()
    path = network_io.write_vtp(result, tmp_path / "y.vtp")
    # the file, read as XML: line cells from u to v, the results as cell and point data
    piece = ET.parse(path).getroot().find("PolyData/Piece")
    assert piece.get("NumberOfLines") == "3" and piece.get("NumberOfPoints") == "4"

    def decoded(a):      # VTK's inline binary: base64 of a UInt64 byte count, then little-endian values
        raw = base64.b64decode(a.text.strip())
        return np.frombuffer(raw[8:8 + int(np.frombuffer(raw[:8], "<u8")[0])], "<f8" if a.get("type") == "Float64"
                             else "<i8")

    cells = {a.get("Name"): decoded(a) for a in piece.findall("CellData/DataArray")}
    points = {a.get("Name"): decoded(a) for a in piece.findall("PointData/DataArray")}
    np.testing.assert_array_equal(cells["flow_rate"], result.flow_rates)
    np.testing.assert_array_equal(cells["strain_u"], result.strain_u)
    np.testing.assert_array_equal(cells["radius"], [2e-3, 1e-3, 1.2e-3])
    np.testing.assert_array_equal(points["pressure"], result.pressures)
    conn = decoded(piece.find("Lines/DataArray[@Name='connectivity']")).reshape(-1, 2)
    assert [(result.nodes[i], result.nodes[j]) for i, j in conn] == [("in", "j"), ("j", "a"), ("j", "b")]
    # read back: the same geometry, walls and boundary conditions (the nodes by their index)
    again = network_io.read_vtp(path, rheology=NEWTONIAN)
    rename = dict(zip(range(4), net.nodes))
    assert [(rename[u], rename[v]) for u, v in again.tube_names] == net.tube_names
    assert network_io.network_table(again)["Rp(m)"] == network_io.network_table(net)["Rp(m)"]
    assert network_io.network_table(again)["h(m)"] == network_io.network_table(net)["h(m)"]
    assert network_io.network_table(again)["Pext"] == [0.0, 10.0, 0.0]
    assert again._resistance == {3: (1e9, 20.0)} and again._pressure == {2: 100.0} and again._inflow == {0: 1e-6}
    np.testing.assert_array_equal(again.solve().pressures, result.pressures)
    layout = network_io.tree_layout(net)
    assert [again.positions[i] for i in range(4)] == [layout[n] for n in net.nodes]


def test_vtp_integer_nodes_and_bad_files(tmp_path):
    net = tubefsi.read_network_table(_y_table(tmp_path / "y.csv"), rheology=NEWTONIAN,
                                     wall=lambda E, h, R: walls["thin-linear"](youngs_modulus=1e6, poisson_ratio=0.5))
    path = network_io.write_vtp(net, tmp_path / "y.vtp", positions={1: (0, 0), 2: (1, 0), 3: (2, 1), 4: (2, -1, 0.5)})
    again = network_io.read_vtp(path, rheology=NEWTONIAN, wall=walls["thin-linear"](youngs_modulus=1e6, poisson_ratio=0.5))
    assert again.nodes == [1, 2, 3, 4] and again.positions[3] == (2.0, 1.0, 0.0)   # (a point has a z: 3-D)
    assert again.positions[4] == (2.0, -1.0, 0.5)
    assert network_io.network_table(again)["Rp(m)"] == network_io.network_table(net)["Rp(m)"]
    bad = tmp_path / "bad.vtp"
    vtk_file = Path(__file__).parent / "data" / "y_written_by_vtk_ascii.vtp"
    bad.write_text(vtk_file.read_text(encoding="utf-8").replace("0.002 0.001 0.0012", "-1 0.001 0.0012"),
                   encoding="utf-8")
    with pytest.raises(InvalidParameterError, match="bad.vtp, cell 0, cell data 'radius'"):
        network_io.read_vtp(bad, rheology=NEWTONIAN)
    bad.write_text("<VTKFile type='UnstructuredGrid'/>", encoding="utf-8")
    with pytest.raises(InvalidParameterError, match="PolyData"):
        network_io.read_vtp(bad, rheology=NEWTONIAN)


def test_tree_layout_is_the_distance_along_the_vessels():
    _, rows = _adan56_rows()
    net = tubefsi.read_network_table(datasets.adan56(), rheology=NEWTONIAN, taper="mean")
    pos = network_io.tree_layout(net)
    length = {int(r[2]): (int(r[1]), float(r[4])) for r in rows}
    for node, (parent, l) in length.items():          # x of a node = x of its parent + the vessel's length
        assert pos[node][0] == pytest.approx(pos[parent][0] + l, rel=1e-14)
    assert pos[1][0] == 0.0


def test_pictures_and_tables(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    _, result = _solved_y()
    for color, unit in (("pressure", "(Pa)"), ("flow_rate", "(mL/min)"), ("strain", "R/a - 1"),
                        ("wall_shear_stress", "(Pa)")):
        ax = result.plot(color=color)
        label = ax.figure.axes[-1].get_ylabel()
        assert unit in label, label
        matplotlib.pyplot.close(ax.figure)
    with pytest.raises(InvalidParameterError, match="color"):
        result.plot(color="speed")
    xr = pytest.importorskip("xarray")
    ds = result.to_xarray(density=1050.0)
    assert isinstance(ds, xr.Dataset) and ds.sizes == {"tube": 3, "node": 4}
    np.testing.assert_array_equal(ds["flow_rate"].values, result.flow_rates)
    np.testing.assert_array_equal(ds["pressure"].values, result.pressures)
    assert ds["pressure"].attrs["units"] == "Pa" and list(ds["u"].values) == ["('in', 'j')".split("'")[1]] + ["j", "j"]
    assert list(ds["tube"].values) == [str(n) for n in result.tube_names]


@pytest.mark.parametrize("mode", ["ascii", "binary"])
def test_vtp_files_written_by_vtk_read_the_same(mode):
    """tests/data/y_written_by_vtk_*.vtp: write_vtp's file of _solved_y, read by VTK 9.7.2's
    vtkXMLPolyDataReader and written again by its vtkXMLPolyDataWriter (ASCII, and binary without
    a compressor): VTK reads write_vtp's file, and read_vtp reads VTK's."""
    net, result = _solved_y()
    path = Path(__file__).parent / "data" / f"y_written_by_vtk_{mode}.vtp"
    again = network_io.read_vtp(path, rheology=NEWTONIAN)
    assert network_io.network_table(again)["Rp(m)"] == network_io.network_table(net)["Rp(m)"]
    assert again._resistance == {3: (1e9, 20.0)} and again._pressure == {2: 100.0} and again._inflow == {0: 1e-6}
    np.testing.assert_allclose(again.solve().pressures, result.pressures, rtol=1e-13)


@settings(max_examples=15, deadline=None)
@given(st.integers(1, 6), st.data())
def test_random_tables_round_trip(tmp_path_factory, n, data):
    """Any table of a random tree (lengths, radii, moduli, thicknesses, external pressures and
    terminal resistances drawn at random) is the table of the network read from it."""
    positive = st.floats(1e-4, 1e-2)
    parents = [data.draw(st.integers(1, k)) for k in range(1, n + 1)]
    lines = ["Name, sn, tn, l(m), Rp(m), E(Pa), h(m), Pext, R1, R2"]
    for k, parent in enumerate(parents):
        r = data.draw(positive)
        lines.append(f"v{k}, {parent}, {k + 2}, {data.draw(st.floats(1e-3, 1.0))!r}, "
                     f"{r!r}, {data.draw(st.floats(1e3, 1e7))!r}, {data.draw(st.floats(0.05, 0.5)) * r!r}, "
                     f"{data.draw(st.floats(-100.0, 100.0))!r}, {data.draw(st.sampled_from([0.0, 1e8, 3.5e9]))!r}, "
                     f"{data.draw(st.sampled_from([0.0, 2e9]))!r}")
    path = tmp_path_factory.mktemp("tables") / "random.csv"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    columns = network_io.network_table(tubefsi.read_network_table(path, rheology=NEWTONIAN))
    rows = [line.split(", ") for line in lines[1:]]
    assert columns["Name"] == [r[0] for r in rows]
    assert columns["sn"] == [int(r[1]) for r in rows] and columns["tn"] == [int(r[2]) for r in rows]
    for key, j in (("l(m)", 3), ("Rp(m)", 4), ("E(Pa)", 5), ("h(m)", 6), ("Pext", 7)):
        assert columns[key] == [float(r[j]) for r in rows]
    assert columns["R1"] == [float(r[8]) + float(r[9]) for r in rows]
    again = tmp_path_factory.mktemp("tables") / "again.csv"
    network_io.write_network_table(tubefsi.read_network_table(path, rheology=NEWTONIAN), again)
    assert network_io.network_table(tubefsi.read_network_table(again, rheology=NEWTONIAN)) == columns


@pytest.mark.parametrize("wall", [walls["thin-linear"](youngs_modulus=1e6, poisson_ratio=0.3),
                                  walls["thick-linear"](youngs_modulus=1e6, poisson_ratio=0.5),
                                  walls["thin-neo-hookean"](shear_modulus=3e5),
                                  walls["thin-linear"](youngs_modulus=1e6, poisson_ratio=0.5, end_condition="open")])
def test_the_table_refuses_a_wall_it_would_read_back_as_another(tmp_path, wall):
    """The table keeps E and h only and reading makes openBF's wall (thin linear, nu = 1/2): a
    thin linear wall with nu = 0.3 once came back with nu = 1/2 (its strain 11 % smaller), a thick
    one as a thin one, silently."""
    net = tubefsi.Network(rheology=NEWTONIAN)
    net.add_tube(1, 2, wall, tubefsi.Tube(radius=2e-3, thickness=2e-4, length=0.1))
    net.set_inflow(1, 1e-6).set_pressure(2, 0.0)
    with pytest.raises(InvalidParameterError, match=r"tube \(1, 2\)"):
        tubefsi.write_network_table(net, tmp_path / "net.csv")


def test_plausible_mistakes_give_typed_errors_naming_the_argument(tmp_path):
    """A missing table file, positions that are not a mapping or whose entry is not a point, and
    an array where a node takes one pressure once gave FileNotFoundError, ValueError and
    TypeError from Python."""
    net = tubefsi.Network(rheology=NEWTONIAN)
    net.add_tube("a", "b", walls["thin-linear"](youngs_modulus=1e6, poisson_ratio=0.5),
                 tubefsi.Tube(radius=1e-3, thickness=1e-4, length=0.1))
    with pytest.raises(InvalidParameterError, match="source must be a readable CSV file"):
        tubefsi.read_network_table(tmp_path / "missing.csv", rheology=NEWTONIAN)
    with pytest.raises(InvalidParameterError, match="positions must be a mapping"):
        network_io.write_vtp(net, tmp_path / "x.vtp", positions="abc")
    with pytest.raises(InvalidParameterError, match=r"positions\['a'\]"):
        network_io.write_vtp(net, tmp_path / "x.vtp", positions={"a": "xy", "b": (0, 1)})
    with pytest.raises(InvalidParameterError, match="pressure .*a single number"):
        net.set_pressure("a", np.array([1.0, 2.0]))


def test_a_tapered_vessel_round_trips_through_vtp(tmp_path):
    """A linear taper written to .vtp (proximal and distal radius and thickness as cell data) is
    read back as the same taper: the same ends, and the same solve (Poiseuille's closed form of a
    linear taper, R = 8 mu L (a_p^2 + a_p a_d + a_d^2) / (3 pi a_p^3 a_d^3), for a stiff wall)."""
    wall = walls["thin-linear"](youngs_modulus=1e15, poisson_ratio=0.5)      # rigid to 1e-12
    net = tubefsi.Network(rheology=NEWTONIAN)
    net.add_tube("in", "out", wall, tubefsi.Tube.tapered(length=0.1, radius=2e-3, outlet_radius=1e-3,
                                                          thickness=2e-4, outlet_thickness=1.5e-4))
    net.set_inflow("in", 1e-6).set_pressure("out", 0.0)
    path = network_io.write_vtp(net, tmp_path / "taper.vtp")
    again = network_io.read_vtp(path, rheology=NEWTONIAN)
    again.set_inflow(0, 1e-6).set_pressure(1, 0.0)
    with pytest.warns(UserWarning, match="reads back as another network"):     # (a thickness not openBF's)
        table = network_io.network_table(again, thickness=False)
    assert (table["Rp(m)"], table["Rd(m)"], table["l(m)"]) == ([2e-3], [1e-3], [0.1])
    a_p, a_d, mu, length = 2e-3, 1e-3, 3.5e-3, 0.1
    resistance = 8 * mu * length * (a_p**2 + a_p * a_d + a_d**2) / (3 * np.pi * a_p**3 * a_d**3)
    for network, inlet in ((net, "in"), (again, 0)):
        assert abs(network.solve().pressure[inlet] / (resistance * 1e-6) - 1) < 1e-9


# ---------------------------------------------------------------------------- round trips that once changed the network
def _same_solve(a, b, a_inlet, b_inlet, q=1e-6):
    """Both networks fed ``q`` at their inlets and solved: the same node pressures and tube
    flow rates, by name (a network read back from a file is the network written)."""
    ra, rb = a.set_inflow(a_inlet, q).solve(), b.set_inflow(b_inlet, q).solve()
    assert rb.nodes == ra.nodes and rb.tube_names == ra.tube_names
    np.testing.assert_allclose(rb.pressures, ra.pressures, rtol=1e-13, atol=0)
    np.testing.assert_allclose(rb.flow_rates, ra.flow_rates, rtol=1e-12, atol=1e-22)
    return ra, rb


def _openbf_y(names=("a", "b", "c"), nodes=(1, 2, 3, 4)):
    wall = network_io.openbf_wall(2e5)
    tube = tubefsi.Tube(radius=1e-3, thickness=2e-4, length=0.05)
    net = tubefsi.Network(rheology=NEWTONIAN)
    n1, n2, n3, n4 = nodes
    net.add_tube(n1, n2, wall, tube, name=names[0])
    net.add_tube(n2, n3, wall, tube, name=names[1])
    net.add_tube(n2, n4, wall, tube, name=names[2])
    return net


def test_distal_pressures_are_written_and_read_back(tmp_path):
    """set_resistance(3, 1e9, distal_pressure=700) was written as R1 only and read back with a
    distal pressure of 0 (the inlet pressure 700 Pa lower), silently. Now a column Pd(Pa) holds
    each outlet's distal pressure; the network read back solves to the same pressures."""
    net = _openbf_y()
    net.set_resistance(3, 1e9, distal_pressure=700.0).set_resistance(4, 2e9, distal_pressure=0.0)
    path = network_io.write_network_table(net, tmp_path / "y.csv")
    assert network_io.network_table(net)["Pd(Pa)"] == [0.0, 700.0, 0.0]
    again = tubefsi.read_network_table(path, rheology=NEWTONIAN)
    assert again._resistance == {3: (1e9, 700.0), 4: (2e9, 0.0)}
    ra, _ = _same_solve(net, again, 1, 1)
    # the outlet's balance (p_3 - 700) / R = q_b: the distal pressure is in the solution
    assert (ra.pressure[3] - 700.0) / 1e9 == pytest.approx(ra.flow_rate["b"], rel=1e-10)


@pytest.mark.parametrize("names", [("#2 branch", "c, left", 'say "hi"'), ("a", "#", "#x,#y")])
def test_names_with_a_hash_a_comma_or_a_quote_read_back(tmp_path, names):
    """A vessel named "#2 branch" was written unquoted and read as a comment line (the vessel and
    its terminal dropped). Such names are quoted now and read back as themselves."""
    net = _openbf_y(names=names)
    net.set_resistance(3, 1e9).set_resistance(4, 1e9)
    again = tubefsi.read_network_table(network_io.write_network_table(net, tmp_path / "n.csv"), rheology=NEWTONIAN)
    assert again.tube_names == list(names) and again._resistance == net._resistance
    _same_solve(net, again, 1, 1)


def test_default_and_numpy_names_read_back_as_the_same_keys(tmp_path):
    """Tuple names (the default (u, v)) were written as the text "('in', 'j')", so that
    flow_rate[("in", "j")] raised KeyError after a round trip, and NumPy nodes as
    "(np.int64(1), np.int64(2))". A default name is written as an empty cell (the reader gives
    (sn, tn) back), a NumPy integer as a plain one."""
    wall, tube = network_io.openbf_wall(2e5), tubefsi.Tube(radius=1e-3, thickness=2e-4, length=0.05)
    net = tubefsi.Network(rheology=NEWTONIAN)
    for u, v in np.array([[1, 2], [2, 3], [2, 4]]):
        net.add_tube(u, v, wall, tube)
    net.set_resistance(np.int64(3), 1e9).set_resistance(np.int64(4), 1e9)
    path = network_io.write_network_table(net, tmp_path / "d.csv")
    assert network_io.network_table(net)["Name"] == [None] * 3
    again = tubefsi.read_network_table(path, rheology=NEWTONIAN)
    assert again.tube_names == [(1, 2), (2, 3), (2, 4)] and all(type(n) is int for n in again.nodes)
    ra, rb = _same_solve(net, again, 1, 1)
    assert rb.flow_rate[(2, 3)] == ra.flow_rate[(np.int64(2), np.int64(3))]
    text = tubefsi.Network(rheology=NEWTONIAN).add_tube("in", "j", wall, tube).add_tube("j", "out", wall, tube)
    text.set_resistance("out", 1e9)
    back = tubefsi.read_network_table(network_io.write_network_table(text, tmp_path / "t.csv"), rheology=NEWTONIAN)
    assert back.tube_names == [("in", "j"), ("j", "out")]
    _same_solve(text, back, "in", "in")


@pytest.mark.parametrize("names, nodes, what", [
    (("a", "12", "c"), (1, 2, 3, 4), "tube name '12'"),               # would read back as the integer 12
    (("a", " b", "c"), (1, 2, 3, 4), "tube name ' b'"),               # the reader strips cells
    (("a", ("x", "y"), "c"), (1, 2, 3, 4), r"tube name \('x', 'y'\)"),  # a tuple other than (u, v)
    (("a", "b", "c"), (1, 2, "3", 4), "node name '3'"),
    (("a", "b", "c"), (1, 2, 3.5, 4), "node name 3.5"),
    (("a", "b", "c"), (1, 2, "3.0", 4), "node name '3.0'"),            # reads back as the node 3
])
def test_names_the_table_would_read_back_as_others_are_refused(tmp_path, names, nodes, what):
    with pytest.raises(InvalidParameterError, match=what):
        network_io.write_network_table(_openbf_y(names=names, nodes=nodes), tmp_path / "x.csv")


@settings(max_examples=25, deadline=None)
@given(st.lists(st.text(min_size=1, max_size=8), min_size=3, max_size=3, unique=True))
def test_any_text_name_reads_back_or_is_refused(tmp_path_factory, names):
    """The contract of the table's names: written and read back as the same name, or refused
    with an InvalidParameterError naming it; never another name."""
    _reads_back_or_is_refused(_openbf_y(names=tuple(names)), tmp_path_factory.mktemp("names") / "n.csv",
                              "tube name", "tube_names", names)


def _reads_back_or_is_refused(net, path, what, attribute, expected):
    """Write ``net``'s table to ``path``: refused naming ``what``, or read back with ``attribute``
    equal to ``expected``."""
    try:
        network_io.write_network_table(net, path)
    except InvalidParameterError as err:
        assert what in str(err)
        return
    assert getattr(tubefsi.read_network_table(path, rheology=NEWTONIAN), attribute) == expected


@settings(max_examples=25, deadline=None)
@given(st.lists(st.one_of(st.text(min_size=1, max_size=6), st.integers(-10**6, 10**6)), min_size=4, max_size=4,
                unique=True))
def test_any_node_name_reads_back_or_is_refused(tmp_path_factory, nodes):
    """The same contract for node names (text or integers; "nan" once read back as an empty
    cell)."""
    _reads_back_or_is_refused(_openbf_y(nodes=tuple(nodes)), tmp_path_factory.mktemp("nodes") / "n.csv",
                              "node name", "nodes", nodes)


def test_a_linear_thickness_along_a_taper_round_trips_through_the_table(tmp_path):
    """A Tube.tapered with a linear thickness could not be written by default ("a constant wall
    thickness (got array of shape (2,))"), and thickness=False read it back with the empirical
    thickness (inlet pressure 1965.9 -> 1983.9 Pa) without a word. Now h(m) and hd(m) hold the two
    ends, a taper whose thickness is the empirical one of its radius keeps an empty h cell (the
    reader's rule), and thickness=False warns."""
    wall = network_io.openbf_wall(4e5)
    net = tubefsi.Network(rheology=NEWTONIAN)
    net.add_tube(1, 2, wall, tubefsi.Tube.tapered(length=0.1, radius=4e-3, outlet_radius=2e-3, thickness=6e-4,
                                                 outlet_thickness=4e-4), name="linear")
    net.add_tube(2, 3, wall, tubefsi.Tube(length=0.1, radius=sampled_linear(2e-3, 1.5e-3, 0.1),
                                          thickness=tubefsi.Profile(network_io._ThicknessOf(
                                              network_io.empirical_thickness, 2e-3, 1.5e-3, 0.1))), name="empirical")
    net.add_tube(2, 4, wall, tubefsi.Tube(length=0.05, radius=1e-3, thickness=3e-4), name="uniform")
    net.set_resistance(3, 1e9).set_resistance(4, 2e9)
    columns = network_io.network_table(net)
    assert columns["h(m)"] == [6e-4, None, 3e-4] and columns["hd(m)"] == [4e-4, None, None]
    again = tubefsi.read_network_table(network_io.write_network_table(net, tmp_path / "t.csv"), rheology=NEWTONIAN)
    _same_solve(net, again, 1, 1)
    assert network_io.network_table(again) == columns
    with pytest.warns(UserWarning, match="tube 'linear'"):
        network_io.network_table(net, thickness=False)


def sampled_linear(a0, a1, length):
    return tubefsi.sampled([0.0, length], [a0, a1], kind="linear")


@pytest.mark.parametrize("graded, field", [("thickness", "thickness"), ("modulus", "wall youngs_modulus")])
def test_a_profile_the_files_cannot_hold_is_refused_or_warned(tmp_path, graded, field):
    """A thickness neither linear nor empirical along the tube, or a modulus that varies along
    it: the table refuses it (naming the tube and the field), a .vtp read back warns (it holds
    the two ends only). A graded modulus once raised a plain TypeError from float()."""
    net = tubefsi.Network(rheology=NEWTONIAN)
    if graded == "thickness":
        wall = network_io.openbf_wall(4e5)
        tube = tubefsi.Tube(length=0.1, radius=2e-3, thickness=tubefsi.Profile(
            lambda z: 2e-4 * (1 + 100 * np.asarray(z) ** 2)))
    else:
        wall = network_io.openbf_wall(tubefsi.sampled([0.0, 0.1], [4e5, 2e5], kind="linear"))
        tube = tubefsi.Tube(length=0.1, radius=2e-3, thickness=2e-4)
    net.add_tube(1, 2, wall, tube, name="bulge")
    with pytest.raises(InvalidParameterError, match=f"tube 'bulge', {field}"):
        network_io.network_table(net)
    path = network_io.write_vtp(net, tmp_path / "b.vtp")
    with pytest.warns(UserWarning, match="cell 0"):
        network_io.read_vtp(path, rheology=NEWTONIAN)


def test_vtp_keeps_numpy_integer_nodes_z_and_the_empirical_taper(tmp_path):
    """NumPy integer node names were not counted as integers (no node array: reading renumbered
    from 0, and set_inflow(1, q) landed on the old node 2); z was dropped; a taper with the
    empirical thickness came back with a linear one (the inlet pressure off by 1.3e-5)."""
    txt = "Name,sn,tn,l(m),Rp(m),Rd(m),E(Pa),R1\na,1,2,0.1,0.004,0.002,400000,0\nb,2,3,0.1,0.002,0.002,400000,1e9\n"
    (tmp_path / "tap.csv").write_text(txt, encoding="utf-8")
    net = tubefsi.read_network_table(tmp_path / "tap.csv", rheology=NEWTONIAN)
    back = network_io.read_vtp(network_io.write_vtp(net, tmp_path / "tap.vtp"), rheology=NEWTONIAN)
    ra = net.set_inflow(1, 2e-6).solve()
    rb = back.set_inflow(1, 2e-6).solve()
    assert back.nodes == [1, 2, 3]
    np.testing.assert_allclose(rb.pressures, ra.pressures, rtol=1e-13, atol=0)
    wall, tube = network_io.openbf_wall(2e5), tubefsi.Tube(radius=1e-3, thickness=2e-4, length=0.05)
    npnet = tubefsi.Network(rheology=NEWTONIAN)
    for u, v in np.array([[1, 2], [2, 3], [2, 4]]):
        npnet.add_tube(u, v, wall, tube)
    npnet.set_pressure(np.int64(3), 0.0).set_pressure(np.int64(4), 0.0)
    for node, xyz in zip(npnet.nodes, [(0, 0, 0), (1, 0, 0), (2, 1, 0.5), (2, -1, -0.5)]):
        npnet.set_position(node, xyz)
    again = network_io.read_vtp(network_io.write_vtp(npnet, tmp_path / "np.vtp"), rheology=NEWTONIAN)
    assert again.nodes == [1, 2, 3, 4] and again._pressure == {3: 0.0, 4: 0.0}
    assert again.positions[3] == (2.0, 1.0, 0.5)
    _same_solve(npnet, again, 1, 1)


@pytest.mark.parametrize("node, value", [("1.5 1.7 3", "1.5"), ("nan 1 3", "nan"), ("1 1 3", "1")])
def test_a_bad_node_array_names_the_file_array_and_point(tmp_path, node, value):
    """A non-integer node array was truncated (1.5 and 1.7 -> 1), NaN became -2**63."""
    net = _openbf_y().set_pressure(1, 100.0).set_pressure(3, 0.0).set_pressure(4, 0.0)
    text = (network_io.write_vtp(net, tmp_path / "y.vtp") and (tmp_path / "y.vtp").read_text())
    root = ET.fromstring(text)
    array = next(a for a in root.iter("DataArray") if a.get("Name") == "node")
    array.attrib.update(format="ascii", type="Float64")
    array.text = node + " 4"
    (tmp_path / "bad.vtp").write_bytes(ET.tostring(root))
    with pytest.raises(InvalidParameterError, match=rf"bad.vtp, point \d, point data 'node'.*got {value}"):
        network_io.read_vtp(tmp_path / "bad.vtp", rheology=NEWTONIAN)


def test_bad_boundary_data_in_a_vtp_names_the_file_and_point(tmp_path):
    net = _openbf_y().set_pressure(1, 100.0).set_pressure(3, 0.0).set_pressure(4, 0.0)
    root = ET.fromstring((tmp_path / "y.vtp").read_text() if network_io.write_vtp(net, tmp_path / "y.vtp") else "")
    array = next(a for a in root.iter("DataArray") if a.get("Name") == "fixed_pressure")
    array.attrib.update(format="ascii", type="Float64")
    array.text = "100 nan -5 0"
    (tmp_path / "bad.vtp").write_bytes(ET.tostring(root))
    with pytest.raises(InvalidParameterError, match=r"bad.vtp, point 2 \(node 3\), point data 'fixed_pressure'"):
        network_io.read_vtp(tmp_path / "bad.vtp", rheology=NEWTONIAN)
    with pytest.raises(InvalidParameterError, match="path must be a file that can be written"):
        network_io.write_vtp(net, tmp_path / "missing" / "y.vtp")
    with pytest.raises(InvalidParameterError, match="path must be a file that can be written"):
        network_io.write_network_table(net, tmp_path / "missing" / "y.csv")


def test_pandas_read_csv_of_adan56_reads_as_the_file():
    """pd.read_csv(adan56()) was refused for its empty "Unnamed: 13" column (openBF's rows end
    with a comma); node ids a DataFrame holds as floats (1.0) became the text '1.0'."""
    pd = pytest.importorskip("pandas")
    frame = pd.read_csv(datasets.adan56())
    assert any(str(c).startswith("Unnamed") for c in frame.columns)
    from_frame = tubefsi.read_network_table(frame, rheology=NEWTONIAN, taper="mean")
    from_file = tubefsi.read_network_table(datasets.adan56(), rheology=NEWTONIAN, taper="mean")
    assert network_io.network_table(from_frame) == network_io.network_table(from_file)
    floats = frame.astype({c: float for c in frame.columns if c.strip() in ("sn", "tn")})
    assert tubefsi.read_network_table(floats, rheology=NEWTONIAN, taper="mean").nodes == from_file.nodes


def test_to_networkx_and_back_keeps_the_names():
    pytest.importorskip("networkx")
    net = _openbf_y(names=("a", None, ("x", 1))).set_inflow(1, 1e-6).set_pressure(3, 0.0)
    net.set_resistance(4, 1e9, distal_pressure=50.0)
    again = tubefsi.Network.from_networkx(net.to_networkx(), rheology=NEWTONIAN)
    assert again.tube_names == ["a", (2, 3), ("x", 1)]
    np.testing.assert_array_equal(again.solve().pressures, net.solve().pressures)


def test_xarray_keeps_numpy_integer_node_names():
    pytest.importorskip("xarray")
    net = tubefsi.Network(rheology=NEWTONIAN)
    for u, v in np.array([[1, 2], [2, 3]]):
        net.add_tube(u, v, "rigid", tubefsi.Tube(radius=1e-3, thickness=2e-4, length=0.05))
    data = net.set_pressure(np.int64(1), 10.0).set_pressure(np.int64(3), 0.0).solve().to_xarray()
    assert data["node"].dtype.kind == "i" and data["node"].values.tolist() == [1, 2, 3]
    assert data["u"].dtype.kind == "i"


def test_a_point_that_is_not_finite_names_the_file_and_point(tmp_path):
    net = _openbf_y().set_pressure(1, 100.0).set_pressure(3, 0.0).set_pressure(4, 0.0)
    root = ET.fromstring((tmp_path / "y.vtp").read_text() if network_io.write_vtp(net, tmp_path / "y.vtp") else "")
    points = root.find("PolyData/Piece/Points/DataArray")
    points.attrib.update(format="ascii", type="Float64")
    points.text = "0 0 0  1 0 0  2 nan 0  2 -1 0"
    (tmp_path / "bad.vtp").write_bytes(ET.tostring(root))
    with pytest.raises(InvalidParameterError, match=r"bad.vtp, point 2, Points must be finite coordinates"):
        network_io.read_vtp(tmp_path / "bad.vtp", rheology=NEWTONIAN)


def test_a_node_written_as_a_float_is_the_integer_node(tmp_path):
    """A file that writes node 2 as "2.0" in one row (a spreadsheet's habit) had the nodes 2 and
    '2.0', two nodes where the table means one: the tree came apart silently."""
    text = "Name,sn,tn,l(m),Rp(m),E(Pa),R1\na,1,2,0.1,0.001,4e5,0\nb,2.0,3,0.1,0.001,4e5,1e9\n"
    net = tubefsi.read_network_table(_write(tmp_path / "f.csv", text), rheology=NEWTONIAN)
    assert net.nodes == [1, 2, 3]


def _write(path, text):
    path.write_text(text, encoding="utf-8")
    return path
