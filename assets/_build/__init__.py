"""Helpers of assets/build.py: signed-distance modelling, meshing, weights, gaits."""
