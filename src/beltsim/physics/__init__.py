"""The discrete model: friction laws, the Eulerian grid, residual and Jacobian kernels."""
