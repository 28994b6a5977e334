"""The software renderer: camera -> rasterizer -> shading -> post, all on the CPU."""

from .bands import all_cores
from .renderer import Frame, render_frame, render_view

__all__ = ["Frame", "all_cores", "render_frame", "render_view"]
