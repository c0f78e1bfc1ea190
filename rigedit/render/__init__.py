"""pyvista/VTK rendering (never Qt): scene actors and the off-screen recorder."""
from .camera import front_vector, up_vector
from .scene import RigScene

__all__ = ["RigScene", "up_vector", "front_vector"]
