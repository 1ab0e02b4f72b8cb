"""GuardToyInterrupt: a pythonfmu FMU with some Python work in every call and every variable type, for
the tests of Ctrl-C and SIGTERM in a Python host."""
from pythonfmu import Boolean, Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real


class GuardToyInterrupt(Fmi2Slave):
    """Some Python work in every call: y = sum of x/k, count = n + steps, positive = flag xor (y > 3)."""
    author = "tests"
    description = "toy"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.x, self.n, self.flag = 1.0, 0, False
        self.y, self.count, self.positive, self.time, self.steps = 0.0, 0, False, 0.0, 0
        self.register_variable(Real("x", causality=Fmi2Causality.input, variability=Fmi2Variability.continuous))
        self.register_variable(Integer("n", causality=Fmi2Causality.input, variability=Fmi2Variability.discrete))
        self.register_variable(Boolean("flag", causality=Fmi2Causality.input, variability=Fmi2Variability.discrete))
        self.register_variable(Real("y", causality=Fmi2Causality.output, variability=Fmi2Variability.continuous))
        self.register_variable(Integer("count", causality=Fmi2Causality.output, variability=Fmi2Variability.discrete))
        self.register_variable(Boolean("positive", causality=Fmi2Causality.output,
                                       variability=Fmi2Variability.discrete))
        self.register_variable(Real("time", causality=Fmi2Causality.output, variability=Fmi2Variability.continuous))

    def do_step(self, current_time, step_size):
        total = 0.0
        for k in range(1, 40):
            total += self.x / k
        self.y = total
        self.steps += 1
        self.count = self.n + self.steps
        self.positive = self.flag != (total > 3.0)
        self.time = current_time + step_size
        return True
