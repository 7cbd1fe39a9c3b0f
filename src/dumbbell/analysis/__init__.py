"""Layer 3, analysis: computations over trajectories (compare, bench, sweep, stability,
rotation). Imports model and solvers; draws and writes through plot and io."""
