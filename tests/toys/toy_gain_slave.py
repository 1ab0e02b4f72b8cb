"""ToyGain: the tests' small pythonfmu FMU beside the project's. y = gain * sqrt(x), ``steps`` counts
fmi2DoStep calls. A deliberate slave bug: x < 0 raises inside do_step (math.sqrt), which pythonfmu
answers with fmi2Fatal. It imports numpy, so the guard's loader has a required module to record."""
import math

import numpy
from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real


class ToyGain(Fmi2Slave):
    author = "tests"
    description = "y = gain * sqrt(x)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.x = 4.0
        self.gain = 1.0
        self.y = 2.0
        self.steps = 0
        self.register_variable(Real("x", causality=Fmi2Causality.input, variability=Fmi2Variability.continuous))
        self.register_variable(Real("gain", causality=Fmi2Causality.parameter, variability=Fmi2Variability.tunable))
        self.register_variable(Real("y", causality=Fmi2Causality.output, variability=Fmi2Variability.continuous))
        self.register_variable(Integer("steps", causality=Fmi2Causality.output,
                                       variability=Fmi2Variability.discrete))

    def do_step(self, current_time, step_size):
        self.y = float(numpy.float64(self.gain) * math.sqrt(self.x))  # ValueError for x < 0
        self.steps += 1
        return True
