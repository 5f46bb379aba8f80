"""contactfem: large-deformation impact-contact with friction after
Wriggers, Vu Van & Stein (1990), on scikit-fem. A teaching and reference toolkit."""

from .laws import check_law

__version__ = "0.1.0"
__all__ = ["check_law"]
