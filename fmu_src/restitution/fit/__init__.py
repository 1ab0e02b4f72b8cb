"""Calibration from drop tests: the model's parameters, and how sure they are, from measured rebounds.

From Python::

    import restitution as r
    from restitution.fit import fit
    cal = fit("drop_pairs.csv", sphere=r.Sphere(r.MATERIALS["chrome_steel"], 6.35e-3),
              plate=r.Plate(r.MATERIALS["al_6061"], 6.35e-3), fit=["plate.Sy"])
    print(cal)              # estimates, 95 % profile-likelihood intervals, noise, with units
    cal.to_dict()           # the same as JSON-ready values

Three kinds of data (:mod:`.reading`, :mod:`.recording`): rebound pairs ``v_in,v_out[,sigma]`` [m/s], one
drop's impact times ``t_impact`` [s], or a WAV recording of the drop. The parts: :mod:`.datasets` (the data
and its checks), :mod:`.forward` (the rebound and the bounce train), :mod:`.likelihood`, :mod:`.estimate`
(least squares, profile-likelihood intervals, identifiability), :mod:`.posterior` (emcee), :mod:`.report`
(table, JSON, plot), :mod:`.calibration` (:func:`fit`); the command line is ``restitution fit``
(:mod:`.command`). docs/calibration.md tells the whole story.
"""
from .calibration import Calibration, fit
from .datasets import DataError, ImpactTimes, Recording, ReboundPairs
from .estimate import FitResult, fit_parameters

__all__ = ["fit", "Calibration", "FitResult", "fit_parameters", "DataError", "ReboundPairs", "ImpactTimes",
           "Recording"]
