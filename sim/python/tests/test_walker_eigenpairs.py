"""The gait's eigenvectors and eigenvalues are those of its stride Jacobian."""

from __future__ import annotations

import numpy as np
import pytest

import walker


@pytest.mark.parametrize("scene", ["compass", "wisse3d", "kneed2d"])
def test_each_eigenpair_satisfies_the_jacobian(scene):
    g = walker.gait(scene)
    n = len(g.names)
    assert g.jacobian.shape == (n, n) and g.eigenvectors.shape == (n, n)
    assert g.eigenvalues.dtype == np.complex128 and g.eigenvectors.dtype == np.complex128
    for k, lam in enumerate(g.eigenvalues):
        v = g.eigenvectors[:, k]
        assert np.linalg.norm(v) == pytest.approx(1.0, abs=1e-9)
        assert np.max(np.abs(g.jacobian @ v - lam * v)) < 1e-8
    # The same spectrum numpy finds.
    ours = np.sort_complex(g.eigenvalues)
    theirs = np.sort_complex(np.linalg.eigvals(g.jacobian))
    np.testing.assert_allclose(ours, theirs, atol=1e-8)
    assert g.max_abs_eigenvalue == pytest.approx(np.max(np.abs(theirs)), abs=1e-10)
