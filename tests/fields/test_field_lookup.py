"""The vector bilinear lookup of the packed field grid against the textbook formula."""

import numba
import numpy as np

from skygas.fields._field_lookup import N_CHANNELS, empty_fields, field_at, prefetch_at


@numba.njit
def _lookup_all(fields, fx, fy):
    out = np.empty((fx.shape[0], N_CHANNELS))
    for k in range(fx.shape[0]):
        prefetch_at(fields, fx[k], fy[k])  # a hint; positions off the grid are clamped
        values = field_at(fields, fx[k], fy[k])
        for c in range(N_CHANNELS):
            out[k, c] = values[c]
    return out


def bilinear(f, fx, fy):
    """f(x, y) = Σ corners w·f, coordinates clamped to the grid (float64 reference)."""
    ny, nx = f.shape[:2]
    fx = np.clip(fx, 0.0, nx - 1.000001)
    fy = np.clip(fy, 0.0, ny - 1.000001)
    i, j = fx.astype(int), fy.astype(int)
    tx, ty = (fx - i)[:, None], (fy - j)[:, None]
    f = f.astype(float)
    return (
        (1 - tx) * (1 - ty) * f[j, i]
        + tx * (1 - ty) * f[j, i + 1]
        + (1 - tx) * ty * f[j + 1, i]
        + tx * ty * f[j + 1, i + 1]
    )


def test_all_channels_match_the_bilinear_formula_inside_and_clamped_outside():
    rng = np.random.default_rng(3)
    fields = empty_fields(37, 53)
    fields[:] = rng.normal(size=fields.shape).astype(np.float32)
    assert fields.ctypes.data % 32 == 0 and fields.flags.c_contiguous
    fx = np.concatenate([rng.uniform(0, 52, 500), [-5.0, 60.0, 0.0, 52.0, 1e9, -1e9]])
    fy = np.concatenate([rng.uniform(0, 36, 500), [3.0, -2.0, 36.0, 0.0, -1e9, 1e9]])
    got = _lookup_all(fields, fx, fy)
    # float64 arithmetic on float32 data: only the summation order may differ (≈ 1e-16)
    np.testing.assert_allclose(got, bilinear(fields, fx, fy), rtol=0, atol=1e-12)


def test_a_linear_field_is_reproduced_exactly_between_nodes():
    fields = empty_fields(10, 12)
    jj, ii = np.mgrid[0:10, 0:12]
    for c in range(N_CHANNELS):
        fields[..., c] = 2.0 * ii - 0.5 * jj + c  # exactly representable in float32
    fx, fy = np.array([0.25, 3.5, 10.75]), np.array([0.5, 8.125, 2.0])
    got = _lookup_all(fields, fx, fy)
    for c in range(N_CHANNELS):
        np.testing.assert_allclose(got[:, c], 2.0 * fx - 0.5 * fy + c, rtol=0, atol=1e-12)
