"""OVF reading and writing: round trips across formats, the header checks, and clear errors."""

import importlib.util
import warnings
from pathlib import Path

import numpy as np
import pytest

from skygas.core.errors import InputError
from skygas.micromag import field_from_array, load_field, read_ovf, write_ovf
from skygas.micromag.ovf import OVFUnitWarning


@pytest.fixture
def field(rng):
    m = rng.normal(size=(2, 5, 7, 3))
    m /= np.linalg.norm(m, axis=-1, keepdims=True)
    return field_from_array(m, (2e-9, 3e-9, 1e-9), origin=(10e-9, -5e-9, 0.0), time=2.5e-9)


@pytest.mark.parametrize("version", [1, 2])
def test_text_bin4_bin8_read_to_the_same_array(tmp_path, field, version):
    arrays = {}
    for fmt in ("text", "bin4", "bin8"):
        path = write_ovf(tmp_path / f"m_{fmt}.ovf", field, fmt=fmt, version=version)
        read = read_ovf(path)
        arrays[fmt] = read.values
        assert read.dims == ("z", "y", "x", "component")
        np.testing.assert_allclose(read.x.values, field.x.values, rtol=1e-12)
        np.testing.assert_allclose(read.y.values, field.y.values, rtol=1e-12)
        np.testing.assert_allclose(read.z.values, field.z.values, rtol=1e-12, atol=1e-24)
        assert read.attrs["dx"] == pytest.approx(2e-9) and read.attrs["dy"] == pytest.approx(3e-9)
        assert read.attrs["time"] == pytest.approx(2.5e-9)
    np.testing.assert_array_equal(arrays["text"], field.values)  # %.17g round-trips exactly
    np.testing.assert_array_equal(arrays["bin8"], arrays["text"])
    # float32 keeps 24 bits: relative error ≤ 2⁻²⁴ per value.
    np.testing.assert_allclose(arrays["bin4"], arrays["text"], rtol=2.0**-24, atol=0)
    assert not np.array_equal(arrays["bin4"], arrays["text"])


def test_mumax3_header_with_desc_time_and_nm_units(tmp_path):
    text = "\n".join(
        [
            "# OOMMF OVF 2.0",
            "# Segment count: 1",
            "# Begin: Segment",
            "# Begin: Header",
            "# Title: m",
            "# meshtype: rectangular",
            "# meshunit: nm",
            "# xmin: 0",
            "# ymin: 0",
            "# zmin: 0",
            "# xmax: 4",
            "# ymax: 2",
            "# zmax: 1",
            "# valuedim: 3",
            "# valuelabels: m_x m_y m_z",
            "# valueunits: 1 1 1",
            "## a comment line",
            "# Desc: Total simulation time:  3e-10  s",
            "# xbase: 1",
            "# ybase: 1",
            "# zbase: 0.5",
            "# xnodes: 2",
            "# ynodes: 1",
            "# znodes: 1",
            "# xstepsize: 2",
            "# ystepsize: 2",
            "# zstepsize: 1",
            "# End: Header",
            "# Begin: Data Text",
            "0 0 1",
            "1 0 0",
            "# End: Data Text",
            "# End: Segment",
            "",
        ]
    )
    path = tmp_path / "m000001.ovf"
    path.write_text(text)
    with pytest.warns(OVFUnitWarning, match="'nm'"):
        read = read_ovf(path)
    np.testing.assert_allclose(read.x.values, [1e-9, 3e-9])
    assert read.attrs["time"] == pytest.approx(3e-10)
    np.testing.assert_array_equal(read.values[0, 0], [[0, 0, 1], [1, 0, 0]])


def test_numpy_input(tmp_path, field):
    np.save(tmp_path / "m.npy", field.values)
    read = load_field(tmp_path / "m.npy", cell_size=(2e-9, 3e-9, 1e-9))
    np.testing.assert_array_equal(read.values, field.values)
    with pytest.raises(InputError, match="cell_size"):
        load_field(tmp_path / "m.npy")


@pytest.mark.parametrize("fmt", ["text", "bin4", "bin8"])
def test_truncated_file(tmp_path, field, fmt):
    path = write_ovf(tmp_path / "m.ovf", field, fmt=fmt)
    raw = path.read_bytes()
    path.write_bytes(raw[: len(raw) // 2 + 40])
    with pytest.raises(InputError, match="m.ovf:data"):
        read_ovf(path)


def test_unknown_header(tmp_path, field):
    path = write_ovf(tmp_path / "m.ovf", field, fmt="text")
    raw = path.read_text()
    (tmp_path / "magic.ovf").write_text(raw.replace("# OOMMF OVF 2.0", "# OOMMF OVF 3.0"))
    with pytest.raises(InputError, match="magic.ovf:header"):
        read_ovf(tmp_path / "magic.ovf")
    (tmp_path / "key.ovf").write_text(raw.replace("# meshtype:", "# meshwarp: 2\n# meshtype:"))
    with pytest.raises(InputError, match="meshwarp"):
        read_ovf(tmp_path / "key.ovf")
    (tmp_path / "fmt.ovf").write_text(raw.replace("Data Text", "Data Binary 16"))
    with pytest.raises(InputError, match="Binary 8"):
        read_ovf(tmp_path / "fmt.ovf")


@pytest.mark.parametrize("fmt", ["text", "bin8"])
def test_nan_data(tmp_path, field, fmt):
    bad = field.copy(data=field.values.copy())
    bad.values[1, 2, 3, 0] = np.nan
    path = write_ovf(tmp_path / "m.ovf", bad, fmt=fmt)
    with pytest.raises(InputError, match="NaN"):
        read_ovf(path)
    with pytest.raises(InputError, match="NaN"):
        field_from_array(bad.values, 1e-9)


@pytest.mark.parametrize("fmt", ["text", "bin4"])
def test_data_block_shorter_than_mesh(tmp_path, field, fmt):
    path = write_ovf(tmp_path / "m.ovf", field, fmt=fmt)
    raw = path.read_bytes()
    if fmt == "text":
        lines = raw.decode().splitlines()
        end = lines.index("# End: Data Text")
        del lines[end - 1]  # drop the last cell
        path.write_text("\n".join(lines) + "\n")
    else:
        start = raw.index(b"# Begin: Data Binary 4\n") + len(b"# Begin: Data Binary 4\n")
        end = raw.index(b"# End: Data")
        # keep the check value and all but the last cell, then the closing lines
        path.write_bytes(raw[:start] + raw[start : end - 1 - 12] + b"\n" + raw[end:])
    with pytest.raises(InputError, match="210 values"):  # 7·5·2 cells × 3
        read_ovf(path)


def test_header_inconsistent_with_mesh(tmp_path, field):
    path = write_ovf(tmp_path / "m.ovf", field, fmt="text")
    text = path.read_text()
    xmax = [line for line in text.splitlines() if line.startswith("# xmax:")][0]
    path.write_text(text.replace(xmax, "# xmax: 1e-6"))
    with pytest.raises(InputError, match="xmax"):
        read_ovf(path)


def test_wrong_check_value_names_endianness(tmp_path, field):
    path = write_ovf(tmp_path / "m.ovf", field, fmt="bin8", version=2)
    raw = path.read_bytes()
    # An OVF 2.0 file with big-endian data (as OVF 1.0 would have) must not be read silently.
    path.write_bytes(
        raw.replace(b"# OOMMF OVF 2.0", b"# OOMMF: rectangular mesh v1.0", 1)
        .replace(b"# valuedim: 3\n", b"")
        .replace(b"# valuelabels: m_x m_y m_z\n", b"")
        .replace(b"# valueunits: 1 1 1\n", b"")
    )
    with pytest.raises(InputError, match="check value"):
        read_ovf(path)


# --- Files from other writers and the header variants they use ----------------------------

WRITERS = Path(__file__).parent / "data" / "ovf_writers"


def _writer_expected_m(x_nm, y_nm, z_nm):
    """The field every writer fixture holds (``generate.expected_m``), at centres in nm."""
    spec = importlib.util.spec_from_file_location("ovf_writers_generate", WRITERS / "generate.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.expected_m(x_nm, y_nm, z_nm)


@pytest.mark.parametrize("name", sorted(p.name for p in WRITERS.glob("*.ovf")))
def test_files_of_independent_writers(name):
    """spirit's ``ovf`` (nm unit, zero-padded segment count, ``##`` after values) and
    discretisedfield: same mesh and values as the analytic field they were written from."""
    path = WRITERS / name
    if name.startswith("spirit"):
        with pytest.warns(OVFUnitWarning, match="'nm'"):
            field = read_ovf(path)
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # a metre mesh gives no warning
            field = read_ovf(path)
    assert field.shape == (2, 4, 5, 3)
    np.testing.assert_allclose(
        field.x.values, (-3.0 + 1.5 * (np.arange(5) + 0.5)) * 1e-9, rtol=1e-12
    )
    np.testing.assert_allclose(
        field.y.values, (1.0 + 2.0 * (np.arange(4) + 0.5)) * 1e-9, rtol=1e-12
    )
    np.testing.assert_allclose(field.z.values, (np.arange(2) + 0.5) * 1e-9, rtol=1e-12)
    assert (field.attrs["dx"], field.attrs["dy"], field.attrs["dz"]) == pytest.approx(
        (1.5e-9, 2e-9, 1e-9), rel=1e-12
    )
    zz, yy, xx = np.meshgrid(
        field.z.values * 1e9, field.y.values * 1e9, field.x.values * 1e9, indexing="ij"
    )
    # text: 12 (spirit) or 17 digits; binary 4: float32 rounding, ≤ 2⁻²⁴ per unit component
    tolerance = 2.0**-24 if "bin4" in name else 1e-11
    np.testing.assert_allclose(field.values, _writer_expected_m(xx, yy, zz), rtol=0, atol=tolerance)


def _hand_written(lines_before_data, data="0 0 1\n1 0 0\n"):
    return (
        "\n".join(["# OOMMF OVF 2.0", *lines_before_data, "# Begin: Data Text"])
        + "\n"
        + data
        + "# End: Data Text\n# End: Segment\n"
    )


_MESH = [
    "# meshunit: m",
    "# xbase: 5e-10",
    "# ybase: 5e-10",
    "# zbase: 5e-10",
    "# xstepsize: 1e-9",
    "# ystepsize: 1e-9",
    "# zstepsize: 1e-9",
    "# xnodes: 2",
    "# ynodes: 1",
    "# znodes: 1",
    "# valuedim: 3",
]


@pytest.mark.parametrize("variant", ["zero-padded", "inline-comments", "shuffled", "case", "crlf"])
def test_header_variants(tmp_path, variant):
    lines = [
        "# Segment count: 1",
        "# Begin: Segment",
        "# Begin: Header",
        "# Title: m",
        *_MESH,
        "# End: Header",
    ]
    if variant == "zero-padded":
        lines = [
            line.replace("count: 1", "count: 000001").replace("nodes: 2", "nodes: 0002")
            for line in lines
        ]
    elif variant == "inline-comments":
        lines = [f"{line}   ## comment: with a colon" if ":" in line else line for line in lines]
        lines.insert(1, "## a whole-line comment")
    elif variant == "shuffled":
        lines = lines[:3] + lines[3:-1][::-1] + lines[-1:]
    elif variant == "case":
        lines = [
            line.replace("nodes", "Nodes").replace("# x", "# X").replace("meshunit", "MeshUnit")
            for line in lines
        ]
    text = _hand_written(lines)
    path = tmp_path / f"{variant}.ovf"
    path.write_bytes(text.replace("\n", "\r\n").encode() if variant == "crlf" else text.encode())
    field = read_ovf(path)
    np.testing.assert_allclose(field.x.values, [0.5e-9, 1.5e-9])
    np.testing.assert_array_equal(field.values[0, 0], [[0, 0, 1], [1, 0, 0]])


@pytest.mark.parametrize(
    "unit, scale", [("nm", 1e-9), ("um", 1e-6), ("µm", 1e-6), ("mm", 1e-3), ("angstrom", 1e-10)]
)
def test_mesh_units_are_converted_with_a_warning(tmp_path, unit, scale):
    lines = [
        line.replace("meshunit: m", f"meshunit: {unit}").replace("e-9", "").replace("5e-10", "0.5")
        for line in _MESH
    ]
    path = tmp_path / "m.ovf"
    path.write_text(_hand_written(lines), encoding="utf-8")
    with pytest.warns(OVFUnitWarning, match=f"'{unit}'"):
        field = read_ovf(path)
    np.testing.assert_allclose(field.x.values, [0.5 * scale, 1.5 * scale], rtol=1e-12)
    assert field.attrs["dx"] == pytest.approx(scale, rel=1e-12)
    assert field.attrs["mesh_unit"] == unit


def test_unknown_mesh_unit_and_several_segments_are_refused(tmp_path):
    path = tmp_path / "m.ovf"
    path.write_text(
        _hand_written([line.replace("meshunit: m", "meshunit: furlong") for line in _MESH])
    )
    with pytest.raises(InputError, match="m.ovf:meshunit = 'furlong'.*nm"):
        read_ovf(path)
    path.write_text(_hand_written(["# Segment count: 0002", *_MESH]))
    with pytest.raises(InputError, match="segment count = '0002'"):
        read_ovf(path)
    path.write_text(_hand_written(["# Segment count: one", *_MESH]))
    with pytest.raises(InputError, match="segment count = 'one'.*a number"):
        read_ovf(path)
