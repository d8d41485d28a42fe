"""microcobot: the desktop micro-manipulation platform's library in Python.

A thin layer over the C++ library (the same calls as the ``microcobot`` command line): numpy
arrays in and out, SI units everywhere (m, s, V, N, Hz), results as dicts of arrays that
``pandas.DataFrame`` takes as they are.

Submodules:
    stickslip  the stick-slip actuator of thesis ch. 2: parameters, simulate, experiments, rollout
    identify   its identification (thesis §2.5.2) from arrays or files (CSV, .mat)
    dsp        Butterworth / Linkwitz-Riley, sosfilt, Welch, MLS, tffit (scipy.signal's signatures)
    control    velocity and position controllers (thesis §2.7) and the closed-loop runs
    platform   scenario runs and recordings (CSV, MCAP, .mat)
    haptics    the dual-stage interface's rendering pipeline (thesis ch. 3), per tick and per block
    tweezers   TéléTweez design calculators (thesis ch. 4, app. A-B)
    vision     the microscope camera: render() a frame as a numpy array, camera_model() its optics
    positioner the 6-DOF parallel positioner (thesis §2.3): Positioner(params) with ik, fk, reachable,
               check, jacobian, conditioning, rotation_range, workspace_slice over (N, 6) arrays
    cell       the assembly cell: Batch(scene, parts, seed).run(mode), summarize(), and batch(config,
               seeds, client) for campaigns of many seeds on Dask

Errors: invalid parameters or inputs raise ``ValueError`` with the command line's one-line
message; a computation that fails (divergence, no convergence) raises
``microcobot.ComputationFailed``. No call returns NaN.
"""

__license__ = "Apache-2.0"  # SPDX identifier (LICENSE)

import sys as _sys

from ._microcobot import (ComputationFailed, __version__, control, dsp, haptics, identify, platform, positioner,
                          stickslip, tweezers, vision)

# `import microcobot.dsp` and `from microcobot.dsp import butter` work like for a package.
for _name in ("stickslip", "identify", "dsp", "control", "platform", "haptics", "tweezers", "vision", "positioner"):
    _sys.modules[__name__ + "." + _name] = globals()[_name]
del _name

from . import cell  # noqa: E402  (pure Python over _microcobot.cell: the Dask campaigns)

__all__ = [
    "ComputationFailed", "__version__", "cell", "control", "dsp", "haptics", "identify", "platform", "positioner",
    "stickslip", "tweezers", "vision"
]
ComputationFailed.__module__ = __name__
