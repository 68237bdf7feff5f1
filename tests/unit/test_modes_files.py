"""Modes files (cosim.bridges.files): .npz and CSV round trips, and every bad file as one line naming the file
and the array (or the CSV file, line and column), read without unpickling and bounded before loading."""
from __future__ import annotations

import os
import zipfile
from pathlib import Path

import numpy as np
import pytest

from cosim.bridges import read_modes, write_modes
from cosim.core.modal_deck import ModalDeck
from cosim.errors import ConfigError


def deck(frame="bridge", slopes=True) -> ModalDeck:
    x, y = np.meshgrid(np.linspace(0, 20, 6), np.linspace(-4, 4, 3), indexing="ij")
    pts = np.column_stack([x.ravel(), y.ravel()])
    phi = np.stack([np.sin(np.pi * pts[:, 0] / 20) * (1 + 0.05 * pts[:, 1]) / 300.0,
                    np.sin(2 * np.pi * pts[:, 0] / 20) / 310.0 + 1e-17])
    phi_x = np.stack([np.pi / 20 * np.cos(np.pi * pts[:, 0] / 20) * (1 + 0.05 * pts[:, 1]) / 300.0,
                      2 * np.pi / 20 * np.cos(2 * np.pi * pts[:, 0] / 20) / 310.0])
    tri = np.array([[0, 3, 4], [0, 4, 1], [1, 4, 5], [1, 5, 2]])
    return ModalDeck(pts + (np.array([1000.0, 2000.0]) if frame == "network" else 0.0), [3.1, 7.123456789012345],
                     phi, frame=frame, phi_x=phi_x if slopes else None, phi_x_minus=0.5 * phi_x if slopes else None,
                     zeta=[0.02, 0.015], modal_mass=[1.0, 1.0 + 1e-9], triangles=tri,
                     quantities={"bending_moment:mid": [1.5e6, -2e4], "strain:bottom": [1e-5, 3e-7]})


def same(a: ModalDeck, b: ModalDeck) -> None:
    for key in ("points", "f_hz", "phi", "phi_x", "phi_x_minus", "zeta", "modal_mass", "triangles"):
        left, right = getattr(a, key), getattr(b, key)
        assert (left is None) == (right is None), key
        if left is not None:
            assert np.array_equal(left, right), key  # bit for bit
    assert a.frame == b.frame
    assert a.quantities.keys() == b.quantities.keys()
    assert all(np.array_equal(a.quantities[k], b.quantities[k]) for k in a.quantities)


@pytest.mark.parametrize("form", ["deck.npz", "deck_csv"])
@pytest.mark.parametrize("frame", ["bridge", "network"])
def test_a_deck_survives_a_round_trip_bit_for_bit(tmp_path, form, frame):
    original = deck(frame, slopes=frame == "bridge")
    path = write_modes(tmp_path / form, original)
    back = read_modes(path, frame=None if form.endswith(".npz") else frame)
    same(original, back)
    assert back.source == os.fspath(path)
    assert np.array_equal(back.rows([3.3, 7.0], [0.1, -2.0]), original.rows([3.3, 7.0], [0.1, -2.0]))


def test_the_csv_form_takes_what_a_commercial_package_exports(tmp_path):
    """Labels that are not numbers, a byte order mark, comments, spaces, theta_y for the slope (w_x = -theta_y),
    rows in any order."""
    folder = tmp_path / "modes"
    folder.mkdir()
    (folder / "points.csv").write_text("\ufeff# joints of the deck\nPoint, X, Y\nJ1, 0, -1\nJ2, 10, -1\nJ3, 0, 1\n"
                                       "J4, 10, 1\n", encoding="utf-8")
    (folder / "modes.csv").write_text("mode,f_hz,modal_mass\n2,9.5,1.0\n1,2.5,1.0\n", encoding="utf-8")
    rows = [(m, p, 0.1 * m + i, 0.01 * i) for m in (1, 2) for i, p in enumerate(["J1", "J2", "J3", "J4"])]
    (folder / "shapes.csv").write_text("mode,point,w,theta_y\n" + "".join(f"{m},{p},{w},{r}\n" for m, p, w, r in
                                                                          reversed(rows)), encoding="utf-8")
    got = read_modes(folder)
    assert list(got.f_hz) == [2.5, 9.5]
    assert got.points.tolist() == [[0, -1], [10, -1], [0, 1], [10, 1]]
    assert got.phi[1].tolist() == pytest.approx([0.2, 1.2, 2.2, 3.2])
    assert got.phi_x is not None and got.phi_x[0].tolist() == pytest.approx([0.0, -0.01, -0.02, -0.03])
    assert got.frame == "bridge" and got.triangles is None


def test_write_refuses_to_overwrite(tmp_path):
    path = write_modes(tmp_path / "d.npz", deck())
    with pytest.raises(ConfigError, match="already exists; refusing to overwrite"):
        write_modes(path, deck())
    write_modes(path, deck(), force=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.npz"]  # no temporary file left


# --------------------------------------------------------------------------------------------- bad .npz
def npz(tmp_path: Path, **change) -> Path:
    good = deck()
    arrays = {"x": good.points[:, 0], "y": good.points[:, 1], "f_hz": good.f_hz, "phi": good.phi,
              "zeta": good.zeta}
    arrays.update(change)
    path = tmp_path / "deck.npz"
    np.savez(path, **{k: v for k, v in arrays.items() if v is not None})
    return path


def _with(array, index, value):
    out = np.array(array, dtype=float)
    out[index] = value
    return out


D = deck()
BAD_NPZ = {
    "shapes disagree": (dict(phi=D.phi[:, :-1]), "phi: expected shape (2, 18)"),
    "y shorter": (dict(y=D.points[:-1, 1]), "y: expected the shape of x"),
    "f not ascending": (dict(f_hz=np.array([7.0, 3.0])), "f_hz: f_hz[1] = 3 Hz is below f_hz[0] = 7 Hz"),
    "f not positive": (dict(f_hz=np.array([0.0, 3.0])), "f_hz: f_hz[0] = 0 Hz"),
    "f nan": (dict(f_hz=np.array([np.nan, 3.0])), "f_hz: f_hz[0] is nan"),
    "phi inf": (dict(phi=_with(D.phi, (1, 4), np.inf)), "phi: phi[1, 4] is inf"),
    "not normalised": (dict(modal_mass=np.array([1.0, 0.25])), "modal_mass: mode 2's shape is not mass-normalised"),
    "missing phi": (dict(phi=None), "phi: missing"),
    "unknown array": (dict(phii=D.phi), "phii: not an array of a modes file"),
    "objects": (dict(phi=np.array([[1, "a"]], dtype=object)), "phi: holds Python objects"),
    "strings": (dict(f_hz=np.array(["3", "7"])), "f_hz: expected numbers"),
    "float triangles": (dict(triangles=np.array([[0.0, 1.0, 2.0]])), "triangles: expected integers"),
    "frame": (dict(frame=np.array("global")), "frame: expected 'bridge' or 'network'"),
    "zeta": (dict(zeta=np.array([0.02, -0.1])), "zeta: zeta[1] = -0.1"),
}


@pytest.mark.parametrize("case", list(BAD_NPZ), ids=list(BAD_NPZ))
def test_a_bad_npz_is_one_line_naming_the_file_and_the_array(tmp_path, case):
    change, text = BAD_NPZ[case]
    path = npz(tmp_path, **change)
    with pytest.raises(ConfigError) as error:
        read_modes(path).rows(1.0, 0.0)
    message = str(error.value)
    assert message.startswith(f"{path}: {text}"), message
    assert "\n" not in message


def test_a_pickled_member_is_refused_before_it_is_loaded(tmp_path):
    """np.load(allow_pickle=True) would run the pickle; cosim reads the header and refuses."""
    path = tmp_path / "deck.npz"
    np.savez(path, x=np.zeros(3), y=np.arange(3.0), f_hz=np.ones(1), phi=np.array([{"a": 1}], dtype=object))
    with pytest.raises(ConfigError, match=r"deck.npz: phi: holds Python objects, which cosim never unpickles"):
        read_modes(path)


def test_a_file_that_is_not_an_npz_is_one_line(tmp_path):
    path = tmp_path / "deck.npz"
    path.write_bytes(b"PK\x03\x04 not a zip at all")
    with pytest.raises(ConfigError, match=r"deck.npz: not a readable .npz file \(.*\); write it with"):
        read_modes(path)
    truncated = npz(tmp_path)
    truncated.write_bytes(truncated.read_bytes()[:-40])
    with pytest.raises(ConfigError, match=r"deck.npz: not a readable .npz file"):
        read_modes(truncated)
    with pytest.raises(ConfigError, match=r"deck.txt: a modes file is a .npz file or a folder of CSV files"):
        (tmp_path / "deck.txt").write_text("x")
        read_modes(tmp_path / "deck.txt")
    with pytest.raises(ConfigError, match=r"nothing.npz: no such modes file"):
        read_modes(tmp_path / "nothing.npz")


def test_sizes_are_checked_from_the_headers_before_any_array_is_loaded(tmp_path, monkeypatch):
    path = npz(tmp_path)
    monkeypatch.setenv("COSIM_MAX_MODE_VALUES", "30")
    with pytest.raises(ConfigError, match=r"deck.npz: phi: 36 values \(an array of shape \(2, 18\)\) is more than the "
                                          r"limit of 30 values .*COSIM_MAX_MODE_VALUES"):
        read_modes(path)
    monkeypatch.delenv("COSIM_MAX_MODE_VALUES")
    monkeypatch.setenv("COSIM_MAX_MODES_FILE_BYTES", "100")
    with pytest.raises(ConfigError, match=r"deck.npz: \d[\d,]* bytes is more than the limit of 100 bytes"):
        read_modes(path)
    monkeypatch.delenv("COSIM_MAX_MODES_FILE_BYTES")
    monkeypatch.setenv("COSIM_MAX_DECK_MODES", "1")
    with pytest.raises(ConfigError, match=r"deck.npz: f_hz: 2 modes is more than the limit of 1 modes"):
        read_modes(path)


def test_a_huge_array_claimed_by_a_small_file_is_refused_unread(tmp_path):
    """A member whose header claims 10^12 values: refused from the header, never allocated."""
    path = npz(tmp_path)
    with zipfile.ZipFile(path, "a") as archive:
        header = b"{'descr': '<f8', 'fortran_order': False, 'shape': (1000000, 1000000), }"
        header += b" " * (117 - len(header)) + b"\n"
        archive.writestr("phi_x.npy", b"\x93NUMPY\x01\x00" + len(header).to_bytes(2, "little") + header)
    with pytest.raises(ConfigError, match=r"deck.npz: phi_x: 1,000,000,000,000 values"):
        read_modes(path)


def test_the_frame_of_the_file_and_the_callers_must_agree(tmp_path):
    path = write_modes(tmp_path / "d.npz", deck("network", slopes=False))
    assert read_modes(path).frame == "network" and read_modes(path, frame="network").frame == "network"
    with pytest.raises(ConfigError, match=r"d.npz: frame: the file's points are in the network frame, but frame = "
                                          "'bridge' was asked for"):
        read_modes(path, frame="bridge")
    with pytest.raises(ConfigError, match=r"`frame` must be one of bridge, network"):
        read_modes(path, frame="world")


# ---------------------------------------------------------------------------------------------- bad CSV
def csv_folder(tmp_path: Path, **files: str) -> Path:
    folder = tmp_path / "modes"
    folder.mkdir()
    base = {
        "points.csv": "point,x,y\n1,0,0\n2,10,0\n3,0,2\n4,10,2\n",
        "modes.csv": "mode,f_hz\n1,2.0\n2,5.0\n",
        "shapes.csv": "mode,point,w\n" + "".join(f"{m},{p},{0.1 * p * m}\n" for m in (1, 2) for p in (1, 2, 3, 4)),
    }
    base.update(files)
    for name, text in base.items():
        if text is not None:
            (folder / name).write_text(text, encoding="utf-8")
    return folder


BAD_CSV = {
    "missing shapes": ({"shapes.csv": None}, "shapes.csv: missing; the CSV form is a folder with"),
    "unknown column": ({"points.csv": "point,x,y,z\n1,0,0,0\n"}, "points.csv:1: unknown column 'z'"),
    "missing column": ({"modes.csv": "mode\n1\n"}, "modes.csv:1: missing column f_hz"),
    "not a number": ({"points.csv": "point,x,y\n1,0,0\n2,ten,0\n"}, "points.csv:3: x: expected a number, "
                                                                             "got 'ten'"),
    "nan": ({"modes.csv": "mode,f_hz\n1,2.0\n2,nan\n"}, "modes.csv:3: f_hz: expected a finite number"),
    "fields": ({"points.csv": "point,x,y\n1,0\n"}, "points.csv:2: expected 3 fields (point,x,y), got 2"),
    "duplicate point": ({"points.csv": "point,x,y\n1,0,0\n2,1,0\n1,0,2\n"},
                        "points.csv:4: point '1' appears twice (first on line 2)"),
    "f order": ({"modes.csv": "mode,f_hz\n1,5.0\n2,2.0\n"}, "modes.csv:3: f_hz: mode 2 (2 Hz) is below mode 1"),
    "f zero": ({"modes.csv": "mode,f_hz\n1,0\n2,2.0\n"}, "modes.csv:2: f_hz: 0 Hz; natural frequencies must"),
    "mode gap": ({"modes.csv": "mode,f_hz\n1,2.0\n3,5.0\n"}, "modes.csv: mode 2 is missing"),
    "mode twice": ({"modes.csv": "mode,f_hz\n1,2.0\n1,5.0\n"}, "modes.csv:3: mode 1 appears twice"),
    "mode text": ({"modes.csv": "mode,f_hz\n1.5,2.0\n"}, "modes.csv:2: mode: expected an integer"),
    "shape missing": ({"shapes.csv": "mode,point,w\n1,1,0.1\n"}, "shapes.csv: mode 1 has no value at point '2'"),
    "shape point": ({"shapes.csv": "mode,point,w\n1,9,0.1\n"}, "shapes.csv:2: point '9' is not in points.csv"),
    "shape mode": ({"shapes.csv": "mode,point,w\n3,1,0.1\n"}, "shapes.csv:2: mode 3 is not in modes.csv"),
    "shape twice": ({"shapes.csv": "mode,point,w\n1,1,0.1\n1,1,0.2\n"}, "shapes.csv:3: mode 1 at point '1' "
                                                                              "appears twice"),
    "both slopes": ({"shapes.csv": "mode,point,w,w_x,theta_y\n1,1,0,0,0\n"}, "shapes.csv: give the slope as"),
    "triangle point": ({"triangles.csv": "a,b,c\n1,2,7\n"}, "triangles.csv:2: c: point '7' is not in"),
    "quantity": ({"quantities.csv": "mode,quantity,sensor,value\n1,moment,mid,3\n"},
                 "quantities.csv:2: 'moment:mid' is not '<quantity>:<sensor>'"),
    "quantity missing mode": ({"quantities.csv": "mode,quantity,sensor,value\n1,bending_moment,mid,3\n"},
                              "quantities.csv: bending_moment:mid has no value for mode 2"),
    "not normalised": ({"modes.csv": "mode,f_hz,modal_mass\n1,2.0,1\n2,5.0,1000\n"},
                       "modal_mass: mode 2's shape is not mass-normalised"),
    "empty": ({"points.csv": "# nothing\n"}, "points.csv: empty; expected the header line point,x,y"),
    "binary": ({"points.csv": None}, "points.csv: not a text file in UTF-8"),
}


@pytest.mark.parametrize("case", list(BAD_CSV), ids=list(BAD_CSV))
def test_a_bad_csv_is_one_line_naming_the_file_line_and_column(tmp_path, case):
    files, text = BAD_CSV[case]
    folder = csv_folder(tmp_path, **files)
    if case == "binary":
        (folder / "points.csv").write_bytes(b"point,x,y\n\xff\xfe\x00\x01\n")
    with pytest.raises(ConfigError) as error:
        read_modes(folder)
    message = str(error.value)
    # a CSV file's message starts with the file (and line); the deck's checks name the folder and the array
    expected = f"{folder}/{text}" if ".csv" in text.split(":")[0] else f"{folder}: {text}"
    assert message.startswith(expected), message
    assert "\n" not in message


def test_a_csv_form_is_bounded_by_the_same_limits(tmp_path, monkeypatch):
    folder = csv_folder(tmp_path)
    monkeypatch.setenv("COSIM_MAX_DECK_POINTS", "3")
    with pytest.raises(ConfigError, match=r"points.csv: 4 points is more than the limit of 3 points"):
        read_modes(folder)
    monkeypatch.delenv("COSIM_MAX_DECK_POINTS")
    monkeypatch.setenv("COSIM_MAX_MODE_VALUES", "7")
    with pytest.raises(ConfigError, match=r"shapes.csv: 8 values \(2 modes x 4 points\) is more than"):
        read_modes(folder)
