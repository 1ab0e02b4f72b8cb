"""Every text an FMU is described by, written from the model's interface table (``models/<model>/``)
alone: no compiler, no pythonfmu, no zip, nothing read from another build.

* :mod:`.fmi2`: FMI 2.0 ``modelDescription.xml`` (the pythonfmu FMU's co-simulation; the native FMU's
  model exchange and co-simulation with its C sources);
* :mod:`.fmi3`: FMI 3.0 ``modelDescription.xml`` and ``sources/buildDescription.xml`` (native);
* :mod:`.c_header`: the C headers the front, the guard and the native backends are compiled against
  (the variable table, value references and codes, the model's identity);
* :mod:`.documentation`: ``documentation/index.html``;
* :mod:`.common`: what they share (generation date and tools, log categories, numbers, units).

The build (:mod:`restitution.fmu.builders`) writes these files into the FMUs; two builds of the same
sources write the same text.
"""
