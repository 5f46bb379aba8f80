"""Studies over many runs: parameter sweeps (sweep.py) and the speed/accuracy
benchmarks (bench.py)."""
