"""Compatibility: automatic weights moved to :mod:`rigedit.binding.weights`."""
from ..binding.weights import *  # noqa: F401,F403
from ..binding.weights import METHODS, compute_weights, default_method, idw_weights  # noqa: F401
