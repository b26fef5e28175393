"""Studies that measure the schemes: convergence, bench, stability, sweeps, the paper."""
