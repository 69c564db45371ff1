"""Which solves of a calibration get more than one torch thread: an LLG piece that a local
cluster runs alone takes every worker's threads; everything else keeps its own."""

from __future__ import annotations

import os

from skygas.calibration.material import load_micromagnetic_material
from skygas.calibration.pipeline import CalibrationJob
from skygas.calibration.plan import CalibrationConfig

CONFIG = CalibrationConfig(material=load_micromagnetic_material("S6"))
CORES = os.cpu_count() or 1


def test_an_llg_piece_alone_takes_every_local_worker():
    job = CalibrationJob(CONFIG, workers=2)
    assert job._threads_for("evolve", ready=1) == min(2, CORES)
    assert job._threads_for("relax", ready=1) == 1


def test_an_llg_piece_beside_other_work_keeps_one_thread():
    job = CalibrationJob(CONFIG, workers=2)
    assert job._threads_for("evolve", ready=3) == 1  # relaxations wait for the other worker
    job._in_flight["laws/pair/3"] = object()  # a relaxation is running
    assert job._threads_for("evolve", ready=1) == 1


def test_threads_are_capped_by_the_cores_and_a_running_cluster_keeps_its_own():
    assert CalibrationJob(CONFIG, workers=4 * CORES)._threads_for("evolve", 1) == CORES
    assert CalibrationJob(CONFIG, workers=1, threads=2)._threads_for("evolve", 1) == 2
    remote = CalibrationJob(CONFIG, workers=2, scheduler="tcp://127.0.0.1:8786")
    assert remote._threads_for("evolve", ready=1) == 1
