import numpy as np
import pytest


class PointCloud:
    """A minimal body for contact tests: free nodes, two dofs each, no stiffness."""

    def __init__(self, X, name="cloud", dof_offset=0):
        self.name = name
        self.X = np.asarray(X, dtype=float)
        self.ndof = 2 * len(self.X)
        self.xdofs = np.arange(self.ndof).reshape(-1, 2)
        self.dof_offset = dof_offset


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
