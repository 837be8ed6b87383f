"""camtool: CAD/CAM for small, home-built and legacy CNC machines."""

__version__ = "0.1.0"
