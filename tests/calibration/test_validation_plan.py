"""The validation's film and starting positions: a disk, or a rectangle whose skyrmions start
near each other and near its edges; both checked in skyrmion diameters, before any solve."""

from __future__ import annotations

import itertools
import math

import pytest

from skygas.calibration import estimate, plan
from skygas.calibration.material import load_micromagnetic_material
from skygas.calibration.plan import CalibrationConfig
from skygas.calibration.validation import outline
from skygas.core.errors import InputError

DIAMETER = 24e-9


def _config(**validation) -> CalibrationConfig:
    return CalibrationConfig(material=load_micromagnetic_material("S6"), validation=validation)


def _edge_distances(film, point):
    x, y = point
    return sorted([x, film.size[0] - x, y, film.size[1] - y])


def test_the_rectangle_is_its_size_in_diameters_and_the_particles_see_its_cells():
    film = plan.validation_film(_config(shape="rectangle", width=4.0, height=3.0), DIAMETER)
    assert not film.disk and film.nx % 2 == 1 and film.ny % 2 == 1
    assert film.size[0] == pytest.approx(4 * DIAMETER, abs=2 * film.cell_size)
    assert film.size[1] == pytest.approx(3 * DIAMETER, abs=2 * film.cell_size)
    shape, radius = outline(film)
    assert radius is None
    assert shape.area() == pytest.approx(film.size[0] * film.size[1], rel=1e-9)


def test_the_rectangles_three_start_near_each_other_and_each_by_one_edge():
    film = plan.validation_film(_config(), DIAMETER)
    points = plan.validation_positions(film, DIAMETER, 3)
    gaps = [math.dist(a, b) / DIAMETER for a, b in itertools.combinations(points, 2)]
    assert 1.29 <= min(gaps) and max(gaps) <= 1.5
    for p in points:
        nearest, second = (d / DIAMETER for d in _edge_distances(film, p)[:2])
        # by one edge (within the edge law's reach), and not in a corner
        assert plan.RECTANGLE_MARGIN - 1e-9 <= nearest <= 0.95 + 1e-9
        assert second >= 1.29


@pytest.mark.parametrize("count", [1, 2, 4])
def test_other_counts_start_apart_and_inside(count):
    film = plan.validation_film(_config(shape="rectangle", width=5.0, height=4.0), DIAMETER)
    points = plan.validation_positions(film, DIAMETER, count)
    assert len(points) == count
    assert all(
        min(_edge_distances(film, p)) >= plan.RECTANGLE_MARGIN * DIAMETER - 1e-15 for p in points
    )
    gaps = [math.dist(a, b) / DIAMETER for a, b in itertools.combinations(points, 2)]
    assert all(1.3 - 1e-9 <= g for g in gaps)
    assert plan.validation_positions(film, DIAMETER, count) == points  # a fixed seed


def test_the_rectangle_is_the_default_and_the_disk_is_kept():
    default = _config().validation
    assert default.shape == "rectangle" and default.min_travel == 0.5
    config = _config(shape="disk")
    film = plan.validation_film(config, DIAMETER)
    assert film.disk
    for x, y in plan.validation_positions(film, DIAMETER, 3):
        assert math.hypot(x - film.radius, y - film.radius) <= film.radius - 0.9 * DIAMETER


def test_a_rectangle_too_small_for_its_skyrmions_is_refused_in_skyrmion_terms():
    with pytest.raises(InputError) as err:
        estimate.check_validation_film(
            _config(shape="rectangle", width=2.0, height=2.0, skyrmions=4)
        )
    assert err.value.field == "validation.skyrmions"
    assert "rectangle of 2 × 2 diameters" in str(err.value)


def test_an_unknown_shape_is_refused():
    with pytest.raises(ValueError, match="disk"):
        _config(shape="hexagon")


def test_the_particles_disk_has_the_area_of_the_magnetic_cells():
    film = plan.validation_film(_config(shape="disk"), DIAMETER)
    shape, radius = outline(film)
    area = film.magnetic().sum() * film.cell_size**2
    assert radius == pytest.approx(math.sqrt(area / math.pi), rel=1e-12)
    assert shape.area() == pytest.approx(area, rel=1e-3)  # a polygon of many sides
