"""The numpy functions under their first module's name; they live in volumes.py and
surfaces.py, and ``import volumetricao`` exposes them all."""
from .surfaces import isosurface_ambient_occlusion, shade
from .volumes import ambient_occlusion, occlusion_sweeping, variance_occlusion_map

__all__ = ["ambient_occlusion", "occlusion_sweeping", "variance_occlusion_map", "isosurface_ambient_occlusion",
           "shade"]
