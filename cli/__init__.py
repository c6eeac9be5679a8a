"""cadcnc's command line (installed as the ``cadcnc`` console script)."""

from .main import main

__all__ = ["main"]
