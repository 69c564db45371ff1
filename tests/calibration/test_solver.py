"""The micromagnetic solver wrapper (magnum.np): the guiding-centre constraint holds a skyrmion
where it is asked to without adding energy, and the solves are pure functions of their inputs
(what makes a resumed calibration bit-identical). Small films on a coarse mesh."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("magnumnp")

from skygas.calibration import solver  # noqa: E402
from skygas.calibration.material import load_micromagnetic_material  # noqa: E402
from skygas.calibration.profile import detect  # noqa: E402

solver.configure(threads=1, compile=False)
MATERIAL = load_micromagnetic_material("S6", cell_size=2e-9)
FILM = solver.Film(41, 41, 2e-9, compensated=True)


def _centre():
    return 0.5 * FILM.size[0], 0.5 * FILM.size[1]


def test_holding_a_symmetric_skyrmion_adds_no_energy():
    """At the film's centre the skyrmion sits where it would sit anyway: the constrained
    minimum is the free one, to the tolerance of the relaxation (let go, the held texture
    finds no lower energy)."""
    fs = solver.FilmSolver(MATERIAL, FILM)
    m0 = solver.skyrmion_texture(FILM, [_centre()], 11e-9, 3e-9)
    held = fs.relax(m0, [_centre()], reach=30e-9, torque_tolerance=1.0)
    free = fs.relax(held.m, torque_tolerance=1.0)
    assert held.converged and free.converged
    assert held.energy == pytest.approx(free.energy, rel=1e-9)
    (s,) = detect(held.m, FILM, MATERIAL.film_thickness)
    assert (s.x, s.y) == pytest.approx(_centre(), abs=0.05 * FILM.cell_size)


def test_a_skyrmion_is_held_off_centre_where_the_edges_push_it():
    fs = solver.FilmSolver(MATERIAL, FILM)
    target = (_centre()[0] - 10e-9, _centre()[1] + 4e-9)
    m0 = solver.skyrmion_texture(FILM, [target], 11e-9, 3e-9)
    held = fs.relax(m0, [target], reach=30e-9, torque_tolerance=1.0)
    (s,) = detect(held.m, FILM, MATERIAL.film_thickness)
    assert (s.x, s.y) == pytest.approx(target, abs=0.1 * FILM.cell_size)
    # let go, it moves towards the centre, where the edges push it, and its energy falls:
    # the hold did something (a thousand steps of the minimiser: some 5 nm of the way)
    free = fs.relax(held.m, torque_tolerance=1.0, max_iterations=1000)
    (f,) = detect(free.m, FILM, MATERIAL.film_thickness)
    assert f.x - target[0] > 1e-9 and f.y < target[1]
    assert held.energy > free.energy


def test_a_skyrmion_held_by_an_edge_is_read_where_it_is_held():
    """The calibration's detector reads the centre the relaxation holds, the edge's tilted band
    included: held 0.7 d_sk from an edge, the skyrmion is read there with all its charge. Left
    out, the band takes a fifth of the charge with it and the centre moves away from the edge,
    the coordinate a law and a track would then disagree on."""
    from skygas.calibration.profile import as_field
    from skygas.micromag.detection import detect_skyrmions

    fs = solver.FilmSolver(MATERIAL, FILM)
    target = (0.7 * 23.2e-9, _centre()[1])
    m0 = solver.skyrmion_texture(FILM, [target], 9e-9, 3e-9)
    held = fs.relax(m0, [target], reach=30e-9, torque_tolerance=10.0)
    assert held.converged
    (s,) = detect(held.m, FILM, MATERIAL.film_thickness)
    assert (s.x, s.y) == pytest.approx(target, abs=0.05 * FILM.cell_size)
    assert abs(s.charge) == pytest.approx(1.0, abs=0.02)
    (without,) = detect_skyrmions(as_field(held.m, FILM, MATERIAL.film_thickness)).skyrmions
    assert abs(without.charge) < 0.9
    assert without.x - target[0] > 0.5 * FILM.cell_size


def test_solves_are_pure_functions_of_their_inputs():
    fs = solver.FilmSolver(MATERIAL, FILM)
    m0 = solver.skyrmion_texture(FILM, [_centre()], 11e-9, 3e-9)
    a = fs.relax(m0, [_centre()], reach=30e-9, torque_tolerance=30.0)
    b = solver.FilmSolver(MATERIAL, FILM).relax(m0, [_centre()], reach=30e-9, torque_tolerance=30.0)
    assert np.array_equal(a.m, b.m) and a.energy == b.energy


def test_llg_is_a_pure_function_and_pieces_agree_with_one_run():
    """The same piece from the same (m, t, next step) gives the same bits (a resumed
    validation run repeats its pieces exactly); cutting a run in two shortens one step, which
    changes the result only within the integrator's tolerance."""
    fs = solver.FilmSolver(MATERIAL, FILM)
    m0 = solver.skyrmion_texture(FILM, [(_centre()[0] - 6e-9, _centre()[1])], 11e-9, 3e-9)
    half = fs.evolve(m0, 0.0, 10e-12, first_step=1e-14)
    again = solver.FilmSolver(MATERIAL, FILM).evolve(m0, 0.0, 10e-12, first_step=1e-14)
    assert np.array_equal(half.m, again.m) and half.next_step == again.next_step
    rest = fs.evolve(half.m, half.time, 10e-12, first_step=half.next_step)
    whole = fs.evolve(m0, 0.0, 20e-12, first_step=1e-14)
    assert rest.time == pytest.approx(whole.time, rel=1e-12)
    assert np.max(np.abs(whole.m - rest.m)) < 1e-4


def test_the_preconditioner_is_symmetric_and_positive():
    """P = (1 − ℓ²∇²)⁻¹ on a padded mesh, cut to the film: ⟨u, Pv⟩ = ⟨Pu, v⟩ and
    ⟨u, Pu⟩ > 0, what makes it a preconditioner whose minimum is the energy's own."""
    import torch

    film = solver.Film(37, 23, 2e-9)
    magnetic = torch.ones((37, 23, 1, 1), dtype=torch.float64)
    p = solver._Smoother(film, 5e-9, magnetic)
    rng = np.random.default_rng(1)
    u, v = (torch.tensor(rng.normal(size=(37, 23, 1, 3))) for _ in range(2))
    assert float((u * p.smooth(v)).sum()) == pytest.approx(float((p.smooth(u) * v).sum()))
    assert float((u * p.smooth(u)).sum()) > 0
    assert float((u * p.sharpen(u)).sum()) > float((u * u).sum())


def test_the_preconditioned_minimiser_finds_magnumnps_minimum_in_fewer_iterations():
    """The free skyrmion relaxed by this module's minimiser and by magnum.np's own
    ``MinimizerBB`` (the unpreconditioned method, independent code): the same energy within
    the two tolerances' reach, and the preconditioner takes fewer iterations."""
    mn = solver.backend()
    fs = solver.FilmSolver(MATERIAL, FILM)
    m0 = solver.skyrmion_texture(FILM, [_centre()], 9e-9, 3e-9)
    ours = fs.relax(m0, torque_tolerance=1.0)
    theirs = solver.FilmSolver(MATERIAL, FILM)
    theirs._set(m0)
    minimizer = mn.MinimizerBB(list(theirs.terms.values()))
    minimizer.minimize(theirs.state, maxiter=20_000, dm_tol=1.0)
    energy = sum(float(t.E(theirs.state)) for t in theirs.terms.values())
    assert ours.converged
    assert ours.energy == pytest.approx(energy, rel=1e-6)
    plain = solver.SMOOTHING_LENGTHS
    try:
        solver.SMOOTHING_LENGTHS = 0.0  # P = 1: MinimizerBB's own steps
        unpreconditioned = solver.FilmSolver(MATERIAL, FILM).relax(m0, torque_tolerance=1.0)
    finally:
        solver.SMOOTHING_LENGTHS = plain
    assert unpreconditioned.energy == pytest.approx(energy, rel=1e-6)
    assert ours.iterations < unpreconditioned.iterations


def test_llg_bits_do_not_depend_on_the_thread_count():
    """A local calibration gives its LLG pieces every core once the relaxations are done
    (``CalibrationJob._threads_for``); a resumed run repeats its pieces to the bit only because
    the thread count leaves LLG's bits alone. A film of 26 000 cells, above torch's grain for
    splitting an operation between threads."""
    import torch

    film = solver.Film(161, 161, 2e-9, compensated=True)
    fs = solver.FilmSolver(MATERIAL, film)
    centre = (0.5 * film.size[0], 0.5 * film.size[1])
    m0 = solver.skyrmion_texture(film, [(centre[0] - 8e-9, centre[1])], 11e-9, 3e-9)
    before = torch.get_num_threads()
    try:
        solver.use_threads(1)
        one = fs.evolve(m0, 0.0, 5e-12, first_step=1e-14)
        solver.use_threads(2)
        assert torch.get_num_threads() == 2
        two = fs.evolve(m0, 0.0, 5e-12, first_step=1e-14)
    finally:
        torch.set_num_threads(before)
    assert one.steps == two.steps > 5
    assert np.array_equal(one.m, two.m) and one.next_step == two.next_step
