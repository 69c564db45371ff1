"""Reading and writing OVF magnetisation files (OOMMF and mumax3), and NumPy arrays.

Supported: OVF 1.0 (``# OOMMF: rectangular mesh v1.0``) and OVF 2.0 (``# OOMMF OVF 2.0``),
single-segment, rectangular meshes, data as ``Text``, ``Binary 4`` or ``Binary 8``. Binary data
are big-endian in OVF 1.0 and little-endian in OVF 2.0, and begin with the check value the format
prescribes (1234567.0 for 4 bytes, 123456789012345.0 for 8 bytes). Values run with x fastest,
then y, then z.

A field is returned as an :class:`xarray.DataArray` with dimensions ``(z, y, x, component)``;
``x``, ``y``, ``z`` are cell-centre coordinates in metres, ``component`` is ``["x", "y", "z"]``.
Its attributes hold the cell size ``dx``, ``dy``, ``dz`` [m], the simulation ``time`` [s] (NaN
when the file does not give one) and the header's ``title``.

Header lines are read as real writers produce them (mumax3, OOMMF, spirit's ``ovf`` library,
discretisedfield): keys in any order and any letter case, zero-padded numbers
(``Segment count: 000001``), ``##`` comments on their own line or after a value
(``valuedim: 3   ## field dimensionality``). The mesh unit may be any of :data:`MESH_UNITS`;
lengths are converted to metres, with an :class:`OVFUnitWarning` when the unit is not the metre
(the OVF format treats the unit as a label, so the conversion is this reader's reading of it).

Every problem with a file (truncated, unknown header line, mesh and header disagreeing, NaN
values, too few values) raises :class:`~skygas.core.errors.InputError` naming the file.
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import cast

import numpy as np
import xarray as xr

from skygas.core.errors import InputError

# First lines, compared after lower-casing and collapsing white space.
_MAGIC = {"# oommf: rectangular mesh v1.0": 1, "# oommf ovf 2.0": 2}
_IRREGULAR_MAGIC = "# oommf: irregular mesh v1.0"
_CHECK_VALUE = {4: 1234567.0, 8: 123456789012345.0}
#: Mesh units the reader converts to metres (factor to metres).
MESH_UNITS = {
    "m": 1.0,
    "cm": 1e-2,
    "mm": 1e-3,
    "um": 1e-6,
    "µm": 1e-6,
    "μm": 1e-6,
    "nm": 1e-9,
    "angstrom": 1e-10,
    "å": 1e-10,
    "pm": 1e-12,
}
_DATA_FORMATS: dict[str, str | int] = {"text": "text", "binary 4": 4, "binary 8": 8}
# The line that closes a data block; searched case-insensitively, spacing as writers vary it.
_END_DATA = re.compile(rb"#[ \t]*end:[ \t]*data", re.I)
# Header keys of both OVF versions (lower case). Anything else is an error: a key we do not
# know might change how the data must be read.
_KNOWN_KEYS = {
    "title",
    "desc",
    "meshunit",
    "meshtype",
    "xbase",
    "ybase",
    "zbase",
    "xstepsize",
    "ystepsize",
    "zstepsize",
    "xnodes",
    "ynodes",
    "znodes",
    "xmin",
    "ymin",
    "zmin",
    "xmax",
    "ymax",
    "zmax",
    "valuedim",
    "valuelabels",
    "valueunits",
    "valueunit",
    "valuemultiplier",
    "valuerangeminmag",
    "valuerangemaxmag",
    "boundary",
    "segment count",
}
_TIME_PATTERN = re.compile(r"total simulation time\s*:\s*([-+0-9.eE]+)\s*(\w*)", re.I)
_TIME_UNITS = {"": 1.0, "s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9, "ps": 1e-12}


class OVFUnitWarning(UserWarning):
    """An OVF file's mesh unit is not the metre; its lengths were converted to metres."""


def _bad(path: Path, what: str, value, allowed: str) -> InputError:
    return InputError(f"{path.name}:{what}", value, allowed)


def _header_line(raw: bytes) -> str:
    """One header line as text, its ``##`` comment (the rest of the line) removed.

    Headers are ASCII in practice; a unit such as "µm" may come in UTF-8 or Latin-1.
    """
    try:
        line = raw.decode("utf-8")
    except UnicodeDecodeError:
        line = raw.decode("latin-1")
    return line.partition("##")[0].strip()


def _parse_header(path: Path, raw: bytes) -> tuple[dict, str | int, int]:
    """Header dict, data format ("text", 4, 8) and the byte offset where the data begin."""
    first_end = raw.find(b"\n")
    first = raw[: first_end if first_end >= 0 else len(raw)].decode("latin-1").strip()
    magic = " ".join(first.lower().split())
    if magic == _IRREGULAR_MAGIC:
        raise _bad(
            path,
            "meshtype",
            "irregular",
            "a rectangular mesh (irregular meshes are "
            "not supported; resample onto a rectangular mesh)",
        )
    if magic not in _MAGIC:
        raise _bad(
            path,
            "header",
            first[:60],
            "a first line '# OOMMF OVF 2.0' or '# OOMMF: rectangular mesh v1.0'",
        )
    header: dict = {"version": _MAGIC[magic], "desc": [], "line": {}}
    pos = first_end + 1
    number = 1
    while True:
        number += 1
        end = raw.find(b"\n", pos)
        if end < 0:
            raise _bad(path, "data", "missing", "a '# Begin: Data ...' line (file truncated?)")
        line = _header_line(raw[pos:end])
        pos = end + 1
        if not line or line == "#":
            continue  # blank lines and comment-only lines
        if not line.startswith("#"):
            raise _bad(path, "header", line[:60], "header lines that start with '#'")
        key, sep, value = line[1:].partition(":")
        key = " ".join(key.lower().split())
        value = value.strip()
        if key == "begin" and value.lower().startswith("data"):
            kind = " ".join(value.lower().removeprefix("data").split())
            fmt = _DATA_FORMATS.get(kind)
            if fmt is None:
                raise _bad(path, "data format", kind, "Text, Binary 4 or Binary 8")
            return header, fmt, pos
        if key in ("begin", "end"):
            continue  # segment and header brackets
        if not sep or key not in _KNOWN_KEYS:
            raise _bad(path, "header", line[1:].strip()[:60], "a known OVF 1.0/2.0 header key")
        if key == "desc":
            header["desc"].append(value)
        else:
            header[key] = value
            header["line"][key] = number


def _number(path: Path, header: dict, key: str, cast=float):
    if key not in header:
        raise _bad(path, key, None, "this header key (required for a rectangular mesh)")
    try:
        return cast(header[key])
    except ValueError:
        raise _bad(path, key, header[key], "a number") from None


def _time_from_header(header: dict) -> float:
    for text in [header.get("title", ""), *header["desc"]]:
        match = _TIME_PATTERN.search(text)
        if match:
            return float(match.group(1)) * _TIME_UNITS.get(match.group(2).lower(), 1.0)
    return math.nan


@dataclass(frozen=True)
class OVFMesh:
    """The rectangular mesh of an OVF file.

    ``nodes`` (nx, ny, nz), ``cell`` (dx, dy, dz) [m] and ``origin``, the mesh corner (xmin, ymin,
    zmin) [m].
    """

    nodes: tuple[int, int, int]
    cell: tuple[float, float, float]
    origin: tuple[float, float, float]

    def same_grid(self, other: OVFMesh) -> bool:
        """Whether ``other`` is this mesh, up to what rounding in a text header leaves.

        Equal node counts, cell sizes within 10⁻⁶ and corners within 10⁻³ of a cell.
        """
        return (
            self.nodes == other.nodes
            and all(
                math.isclose(a, b, rel_tol=1e-6) for a, b in zip(self.cell, other.cell, strict=True)
            )
            and all(
                abs(a - b) <= 1e-3 * c
                for a, b, c in zip(self.origin, other.origin, self.cell, strict=True)
            )
        )

    def describe(self, origin: bool = False) -> str:
        """The mesh in words: ``200 × 125 cells of 2 nm``.

        ``2 × 2.5 nm`` for cells that are not square; the layers if there are several, and the
        corner if ``origin``.
        """
        nx, ny, nz = self.nodes
        dx, dy, dz = self.cell
        cell = (
            _length(dx)
            if math.isclose(dx, dy, rel_tol=1e-6)
            else f"{_number_nm(dx)} × {_length(dy)}"
        )
        text = f"{nx} × {ny} cells of {cell}"
        if nz > 1:
            text += f", {nz} layers of {_length(dz)}"
        if origin:
            text += ", corner at (" + ", ".join(_number_nm(v) for v in self.origin) + ") nm"
        return text


def _number_nm(value: float) -> str:
    return f"{value * 1e9:.4g}"


def _length(value: float) -> str:
    """A length [m] in nm, as short as the value allows."""
    return f"{_number_nm(value)} nm"


def _mesh_of(path: Path, header: dict) -> tuple[list[int], list[float], list[float], float]:
    """Node counts, steps and first cell centres (in the file's unit) and metres per unit.

    After checking the mesh against its own bounding box.
    """
    if "segment count" in header and _number(path, header, "segment count", int) != 1:
        raise _bad(path, "segment count", header["segment count"], "1 (one field per file)")
    if header.get("meshtype", "rectangular").lower() != "rectangular":
        raise _bad(path, "meshtype", header["meshtype"], "rectangular")
    unit = header.get("meshunit", "m")
    scale = _mesh_scale(path, unit, header["line"].get("meshunit", 1))
    nodes = [_number(path, header, f"{a}nodes", int) for a in "xyz"]
    steps = [_number(path, header, f"{a}stepsize") for a in "xyz"]
    bases = [_number(path, header, f"{a}base") for a in "xyz"]
    if min(nodes) < 1 or min(steps) <= 0:
        raise _bad(path, "nodes/stepsize", (nodes, steps), "positive node counts and steps")
    # The mesh must agree with its own bounding box: xmax − xmin = xnodes·xstepsize and the
    # first cell centre xbase = xmin + xstepsize/2.
    for axis, n, step, base in zip("xyz", nodes, steps, bases, strict=True):
        if f"{axis}min" in header and f"{axis}max" in header:
            lo, hi = _number(path, header, f"{axis}min"), _number(path, header, f"{axis}max")
            if not math.isclose(hi - lo, n * step, rel_tol=1e-4, abs_tol=1e-6 * step):
                raise _bad(
                    path,
                    f"{axis}max",
                    hi,
                    f"{axis}min + {axis}nodes·{axis}stepsize "
                    f"= {lo + n * step:g} (header inconsistent)",
                )
            if not math.isclose(base, lo + step / 2, rel_tol=1e-4, abs_tol=1e-3 * step):
                raise _bad(
                    path,
                    f"{axis}base",
                    base,
                    f"{axis}min + {axis}stepsize/2 = {lo + step / 2:g} (header inconsistent)",
                )
    return nodes, steps, bases, scale


# The header ends with the line that opens the data block.
_BEGIN_DATA = re.compile(rb"#[ \t]*begin:[ \t]*data[^\n]*\n", re.I)


def read_mesh(path: str | Path) -> OVFMesh:
    """The mesh of an OVF file from its header only (the data are not read).

    Cheap enough to check a whole folder of snapshots before reading any of them.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError("path", str(path), "an existing OVF file")
    raw = b""
    with path.open("rb") as f:
        while not _BEGIN_DATA.search(raw):
            chunk = f.read(1 << 16)
            if not chunk:
                break  # _parse_header says what is missing
            raw += chunk
    header, _, _ = _parse_header(path, raw)
    (nx, ny, nz), (dx, dy, dz), (bx, by, bz), scale = _mesh_of(path, header)
    return OVFMesh(
        (nx, ny, nz),
        (dx * scale, dy * scale, dz * scale),
        ((bx - dx / 2) * scale, (by - dy / 2) * scale, (bz - dz / 2) * scale),
    )


def read_ovf(path: str | Path) -> xr.DataArray:
    """Read one OVF 1.0/2.0 file (text, binary 4 or binary 8) into a DataArray (see module)."""
    path = Path(path)
    if not path.is_file():
        raise InputError("path", str(path), "an existing OVF file")
    raw = path.read_bytes()
    header, fmt, start = _parse_header(path, raw)
    nodes, steps, bases, scale = _mesh_of(path, header)
    unit = header.get("meshunit", "m")
    dim = _number(path, header, "valuedim", int) if header["version"] == 2 else 3
    if dim != 3:
        raise _bad(path, "valuedim", dim, "3 (a vector field)")
    count = nodes[0] * nodes[1] * nodes[2] * dim
    values = _read_values(path, raw, start, fmt, count, header["version"])
    if "valuemultiplier" in header:
        values = values * _number(path, header, "valuemultiplier")
    if not np.all(np.isfinite(values)):
        bad = int(np.flatnonzero(~np.isfinite(values))[0]) // dim
        raise _bad(path, "data", "NaN/inf", f"finite values (first bad cell: index {bad})")
    array = values.reshape(nodes[2], nodes[1], nodes[0], dim)
    coords = {
        a: (a, (base + step * np.arange(n)) * scale)
        for a, n, step, base in zip("xyz", nodes, steps, bases, strict=True)
    }
    return xr.DataArray(
        array,
        dims=("z", "y", "x", "component"),
        coords={**coords, "component": ["x", "y", "z"]},
        attrs={
            "dx": steps[0] * scale,
            "dy": steps[1] * scale,
            "dz": steps[2] * scale,
            "time": _time_from_header(header),
            "title": header.get("title", ""),
            "source": str(path),
            "ovf_version": header["version"],
            "mesh_unit": unit,
        },
        name="m",
    )


# Warnings already shown (the registry of warnings.warn_explicit): one per unit and header line,
# not one per snapshot of a run.
_SHOWN: dict = {}


def _mesh_scale(path: Path, unit: str, line: int) -> float:
    """Metres per mesh unit; warns (:class:`OVFUnitWarning`) when the unit is not the metre.

    The warning points at the file and its ``meshunit`` line (``FILE:LINE: OVFUnitWarning: …``).
    """
    scale = MESH_UNITS.get(unit.lower())
    if scale is None:
        raise _bad(
            path,
            "meshunit",
            unit,
            f"one of {', '.join(MESH_UNITS)} (edit the header's "
            "'# meshunit:' line to the unit the mesh was written in)",
        )
    if scale != 1.0:
        warnings.warn_explicit(
            f"mesh unit {unit!r}: lengths converted to metres (× {scale:g})",
            OVFUnitWarning,
            str(path),
            line,
            module=__name__,
            registry=_SHOWN,
        )
    return scale


def _read_values(path: Path, raw: bytes, start: int, fmt, count: int, version: int):
    if fmt == "text":
        found = _END_DATA.search(raw, start)
        end = -1 if found is None else found.start()
        if end < 0:
            raise _bad(path, "data", "no '# End: Data Text'", "a complete file (truncated?)")
        try:
            values = np.array(raw[start:end].split(), dtype=np.float64)
        except ValueError:
            raise _bad(path, "data", "non-numeric text", "numbers only") from None
        if values.size != count:
            raise _bad(
                path,
                "data",
                f"{values.size} values",
                f"{count} values (xnodes·ynodes·znodes·valuedim)",
            )
        return values
    width = fmt
    dtype = np.dtype(f"{'>' if version == 1 else '<'}f{width}")
    need = width * (count + 1)
    # The closing line must follow the values; where it comes earlier, the block is short.
    # (Searching binary data for the marker could in principle hit by chance, so it is only
    # used to explain an error, never to delimit the values.)
    found = _END_DATA.search(raw, start)
    closing = -1 if found is None else found.start()
    if len(raw) - start < need or (0 <= closing < start + need):
        available = (closing if 0 <= closing < start + need else len(raw)) - start
        have = max(0, available // width - 1)
        raise _bad(
            path,
            "data",
            f"{have} values",
            f"{count} values of binary {width} "
            "(xnodes·ynodes·znodes·valuedim; file truncated or data block short)",
        )
    check = np.frombuffer(raw, dtype=dtype, count=1, offset=start)[0]
    if check != _CHECK_VALUE[width]:
        raise _bad(
            path,
            "check value",
            float(check),
            f"{_CHECK_VALUE[width]} ({'big' if version == 1 else 'little'}-endian OVF {version}.0)",
        )
    values = np.frombuffer(raw, dtype=dtype, count=count, offset=start + width)
    if not _END_DATA.match(raw[start + need :].lstrip()):
        raise _bad(
            path,
            "data",
            "more values than the mesh, or no '# End: Data'",
            f"exactly {count} values (xnodes·ynodes·znodes·valuedim) then '# End: Data'",
        )
    return values.astype(np.float64)


def field_from_array(
    values,
    cell_size: tuple[float, float, float] | float,
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0),
    time: float = math.nan,
    title: str = "m",
) -> xr.DataArray:
    """Wrap a NumPy array of shape (nz, ny, nx, 3) or (ny, nx, 3) as a field DataArray.

    ``cell_size`` [m] is (dx, dy, dz) or one number for cubic cells; ``origin`` [m] is the
    corner of the mesh (the first cell centre is origin + cell/2).
    """
    array = np.asarray(values, dtype=np.float64)
    if array.ndim == 3:
        array = array[np.newaxis]
    if array.ndim != 4 or array.shape[-1] != 3:
        raise InputError("values.shape", array.shape, "(nz, ny, nx, 3) or (ny, nx, 3)")
    if not np.all(np.isfinite(array)):
        raise InputError("values", "NaN/inf", "finite magnetisation values")
    # np.isscalar's guard says "any NumPy or Python scalar", not which of the annotated types
    if np.isscalar(cell_size):
        cells: tuple[float, ...] = (float(cast(float, cell_size)),) * 3
    else:
        cells = tuple(map(float, cast(tuple[float, float, float], cell_size)))
    if len(cells) != 3 or min(cells) <= 0:
        raise InputError("cell_size", cell_size, "three positive lengths in metres")
    nz, ny, nx, _ = array.shape
    coords = {
        a: (a, origin[i] + cells[i] * (np.arange(n) + 0.5))
        for i, (a, n) in enumerate(zip("xyz", (nx, ny, nz), strict=True))
    }
    return xr.DataArray(
        array,
        dims=("z", "y", "x", "component"),
        coords={**coords, "component": ["x", "y", "z"]},
        attrs={
            "dx": cells[0],
            "dy": cells[1],
            "dz": cells[2],
            "time": float(time),
            "title": title,
            "source": "array",
            "ovf_version": 0,
        },
        name="m",
    )


def load_field(source, cell_size=None) -> xr.DataArray:
    """A field from an OVF path, a ``.npy`` path, a NumPy array or a field DataArray.

    NumPy input needs ``cell_size`` [m] since the array carries no mesh.
    """
    if isinstance(source, xr.DataArray):
        return source
    if isinstance(source, (str, Path)) and Path(source).suffix.lower() != ".npy":
        return read_ovf(source)
    if cell_size is None:
        raise InputError("cell_size", None, "the cell size in metres for NumPy input")
    values = np.load(source) if isinstance(source, (str, Path)) else source
    return field_from_array(values, cell_size)


def write_ovf(
    path: str | Path,
    field: xr.DataArray,
    fmt: str = "bin4",
    version: int = 2,
    time: float | None = None,
    notes: Sequence[str] = (),
) -> Path:
    """Write a field DataArray as OVF ``version`` 1 or 2, ``fmt`` "text", "bin4" or "bin8".

    The header follows what mumax3 writes (metre mesh unit, ``Desc: Total simulation time``);
    each of ``notes`` becomes one more ``Desc`` line.
    """
    if fmt not in ("text", "bin4", "bin8"):
        raise InputError("fmt", fmt, "text, bin4 or bin8")
    if version not in (1, 2):
        raise InputError("version", version, "1 or 2")
    path = Path(path)
    array = np.asarray(field.transpose("z", "y", "x", "component").values, dtype=np.float64)
    nz, ny, nx, _ = array.shape
    cells = [float(field.attrs["dx"]), float(field.attrs["dy"]), float(field.attrs["dz"])]
    firsts = [float(field[a].values[0]) for a in "xyz"]
    when = field.attrs.get("time", math.nan) if time is None else time
    lines = [
        "# OOMMF OVF 2.0" if version == 2 else "# OOMMF: rectangular mesh v1.0",
        "# Segment count: 1",
        "# Begin: Segment",
        "# Begin: Header",
        f"# Title: {field.attrs.get('title', 'm')}",
        "# meshtype: rectangular",
        "# meshunit: m",
    ]
    for a, first, step, n in zip("xyz", firsts, cells, (nx, ny, nz), strict=True):
        lines += [f"# {a}min: {first - step / 2!r}", f"# {a}max: {first - step / 2 + n * step!r}"]
    if version == 2:
        lines += ["# valuedim: 3", "# valuelabels: m_x m_y m_z", "# valueunits: 1 1 1"]
    else:
        lines += [
            "# valueunit: 1",
            "# valuemultiplier: 1",
            "# ValueRangeMinMag: 1e-08",
            "# ValueRangeMaxMag: 1",
        ]
    lines += [f"# Desc: {note}" for note in notes]
    if when is not None and math.isfinite(when):
        lines.append(f"# Desc: Total simulation time:  {when!r}  s")
    for a, first, step, n in zip("xyz", firsts, cells, (nx, ny, nz), strict=True):
        lines += [f"# {a}base: {first!r}", f"# {a}stepsize: {step!r}", f"# {a}nodes: {n}"]
    lines.append("# End: Header")
    label = {"text": "Text", "bin4": "Binary 4", "bin8": "Binary 8"}[fmt]
    lines.append(f"# Begin: Data {label}")
    flat = array.reshape(-1, 3)
    with path.open("wb") as out:
        out.write(("\n".join(lines) + "\n").encode("utf-8"))
        if fmt == "text":
            np.savetxt(out, flat, fmt="%.17g")
        else:
            width = 4 if fmt == "bin4" else 8
            dtype = np.dtype(f"{'>' if version == 1 else '<'}f{width}")
            out.write(np.array([_CHECK_VALUE[width]], dtype=dtype).tobytes())
            out.write(flat.astype(dtype).tobytes())
            out.write(b"\n")
        out.write(f"# End: Data {label}\n# End: Segment\n".encode("ascii"))
    return path
