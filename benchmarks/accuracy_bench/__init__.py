"""The parts of benchmarks/bench_accuracy.py, one job each: its configuration and goals, the
independent reference, the timing harness, the measurements (Zener methods, the whole model, FMU round
trips, e44 against e45, the bouncing ball), the page and its figure."""
