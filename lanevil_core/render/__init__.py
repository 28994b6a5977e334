"""The software renderer: camera -> rasterizer -> shading -> post, all on the CPU."""

from .renderer import Frame, render_frame

__all__ = ["Frame", "render_frame"]
