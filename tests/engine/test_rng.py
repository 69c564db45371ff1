"""The counter-based generator: Philox4x32-10 known answers and Gaussian statistics."""

import numba
import numpy as np
import pytest
from scipy import stats

from skygas.engine._rng import fill_gaussian_pairs, gaussians, philox_words

# Known-answer vectors of Philox4x32-10 (Random123, kat_vectors).
KAT = [
    ([0, 0, 0, 0], [0, 0], [0x6627E8D5, 0xE169C58D, 0xBC57AC4C, 0x9B00DBD8]),
    ([0xFFFFFFFF] * 4, [0xFFFFFFFF] * 2, [0x408F276D, 0x41C83B0E, 0xA20BC7C6, 0x6D5451FD]),
    (
        [0x243F6A88, 0x85A308D3, 0x13198A2E, 0x03707344],
        [0xA4093822, 0x299F31D0],
        [0xD16CFE09, 0x94FDCCEB, 0x5001E420, 0x24126EA1],
    ),
]


@pytest.mark.parametrize("counter,key,expected", KAT)
def test_philox_known_answers(counter, key, expected):
    assert philox_words(counter, key) == expected


def test_gaussians_are_standard_normal_and_independent():
    z = gaussians(seed=1234, ident=17, steps=np.arange(200_000))
    n = len(z)
    for axis in range(2):
        assert abs(z[:, axis].mean()) < 4 / np.sqrt(n)
        assert abs(z[:, axis].var() - 1) < 4 * np.sqrt(2 / n)
        assert stats.kstest(z[:, axis], "norm").pvalue > 1e-3
    # the two components, consecutive steps and neighbouring ids are uncorrelated
    assert abs(np.corrcoef(z[:, 0], z[:, 1])[0, 1]) < 4 / np.sqrt(n)
    assert abs(np.corrcoef(z[:-1, 0], z[1:, 0])[0, 1]) < 4 / np.sqrt(n)
    other = gaussians(seed=1234, ident=18, steps=np.arange(200_000))
    assert abs(np.corrcoef(z[:, 0], other[:, 0])[0, 1]) < 4 / np.sqrt(n)
    assert not np.array_equal(z, gaussians(seed=1235, ident=17, steps=np.arange(200_000)))


def test_batched_generation_equals_the_scalar_definition():
    @numba.njit
    def batch(ids, alive, step):
        n = ids.shape[0]
        out_x, out_y, cand = np.zeros(n), np.zeros(n), np.empty((4, n))
        fill_gaussian_pairs(99, ids, alive, step, 0, cand, out_x, out_y)
        return out_x, out_y

    ids = np.arange(500, dtype=np.int64) * 7 + 3
    alive = np.ones(500, dtype=np.bool_)
    for step in (0, 1, 12345):
        bx, by = batch(ids, alive, step)
        for k in range(0, 500, 37):
            ref = gaussians(99, int(ids[k]), [step])[0]
            assert (bx[k], by[k]) == (ref[0], ref[1])
