#!/bin/sh
# Regenerates the shipped movie chamber-movie.tif and its sidecars from their seeds
# (docs/tracking.md): the simulation (seed 28 in chamber.toml), then the microscope picture
# (noise seed 1). Run from the repository's root: sh examples/tracking/make-movie.sh
set -e
skygas simulate examples/tracking/chamber.toml --out out/tracking-gas --overwrite --quiet
skygas render out/tracking-gas --out examples/tracking/chamber-movie.tif --overwrite \
    --start 602e-9 --pixel-size 14e-9 --psf-sigma 20e-9 --margin 38.2e-9 \
    --noise 2 --photons 20000 --illumination-drift 0.05 --seed 1 --quiet
