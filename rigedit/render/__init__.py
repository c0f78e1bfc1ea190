"""pyvista/VTK rendering (never Qt): scene actors and the off-screen recorder."""
from .scene import RigScene, front_vector, up_vector

__all__ = ["RigScene", "up_vector", "front_vector"]
