from . import cell as cell
from . import control as control
from . import dsp as dsp
from . import haptics as haptics
from . import identify as identify
from . import platform as platform
from . import positioner as positioner
from . import stickslip as stickslip
from . import tweezers as tweezers
from . import vision as vision

__version__: str

class ComputationFailed(RuntimeError):
    """A computation could not produce a valid result (divergence, no convergence): CLI exit 4."""

__all__ = ["ComputationFailed", "__version__", "cell", "control", "dsp", "haptics", "identify", "platform", "positioner",
           "stickslip", "tweezers", "vision"]
