"""Write the OVF fixtures of this folder with two independent OVF writers.

Not part of the test suite: it was run once, in a separate environment with
``pip install ovf==0.4.3 discretisedfield==0.92.0`` (spirit's OVF library, a C library with a
Python wrapper, and ubermag's discretisedfield). The tests read the files it made and compare
them with :func:`expected_m`, evaluated at the cell centres the reader returns.

Mesh: 5 × 4 × 2 cells of 1.5 × 2 × 1 nm, corner at (−3, 1, 0) nm.
"""

import os

import numpy as np

NODES = (5, 4, 2)  # x, y, z
CELL_NM = (1.5, 2.0, 1.0)
CORNER_NM = (-3.0, 1.0, 0.0)


def expected_m(x_nm, y_nm, z_nm):
    """The unit field written to every file, at cell centres given in nm (any shape)."""
    a = 0.4 + 0.3 * x_nm - 0.2 * y_nm
    b = 0.5 * z_nm + 0.25 * y_nm
    return np.stack([np.sin(a) * np.cos(b), np.sin(a) * np.sin(b), np.cos(a)], axis=-1)


def _centres_nm():
    return [c + s * (np.arange(n) + 0.5) for c, s, n in zip(CORNER_NM, CELL_NM, NODES, strict=True)]


def write_spirit(folder):
    from ovf import ovf  # spirit's OVF library

    x, y, z = _centres_nm()
    zz, yy, xx = np.meshgrid(z, y, x, indexing="ij")
    m = expected_m(xx, yy, zz).reshape(-1, 3)  # x fastest, then y, then z
    upper = [c + s * n for c, s, n in zip(CORNER_NM, CELL_NM, NODES, strict=True)]
    for fmt, name, dtype in [
        (ovf.FILEFORMAT_TEXT, "text", "d"),
        (ovf.FILEFORMAT_BIN4, "bin4", "f"),
        (ovf.FILEFORMAT_BIN8, "bin8", "d"),
    ]:
        segment = ovf.ovf_segment(
            title="m",
            comment="written by spirit's ovf 0.4.3",
            valuedim=3,
            valueunits="1 1 1",
            valuelabels="m_x m_y m_z",
            meshtype="rectangular",
            meshunits="nm",
            n_cells=list(NODES),
            step_size=list(CELL_NM),
            bounds_min=list(CORNER_NM),
            bounds_max=upper,
            origin=[c + s / 2 for c, s in zip(CORNER_NM, CELL_NM, strict=True)],
        )
        path = os.path.join(folder, f"spirit-ovf-0.4.3-{name}.ovf")
        if os.path.exists(path):
            os.remove(path)
        with ovf.ovf_file(path) as handle:
            assert handle.write_segment(segment, np.ascontiguousarray(m, dtype=dtype), fmt) == -1


def write_discretisedfield(folder):
    import discretisedfield as df

    corner = [c * 1e-9 for c in CORNER_NM]
    upper = [(c + s * n) * 1e-9 for c, s, n in zip(CORNER_NM, CELL_NM, NODES, strict=True)]
    mesh = df.Mesh(p1=corner, p2=upper, cell=[s * 1e-9 for s in CELL_NM])

    def value(point):
        return tuple(expected_m(*(np.asarray(point) * 1e9)))

    field = df.Field(mesh, nvdim=3, value=value)
    for name in ("txt", "bin4", "bin8"):
        field.to_file(
            os.path.join(folder, f"discretisedfield-0.92.0-{name}.ovf"), representation=name
        )


if __name__ == "__main__":
    here = os.path.dirname(os.path.abspath(__file__))
    write_spirit(here)
    write_discretisedfield(here)
