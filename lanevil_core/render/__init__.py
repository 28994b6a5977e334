"""The software renderer: camera -> rasterizer -> shading -> post, all on the CPU."""

from .renderer import Frame, render_frame, render_view

__all__ = ["Frame", "render_frame", "render_view"]
