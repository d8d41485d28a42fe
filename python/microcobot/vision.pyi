"""The microscope camera (issue #27): rendered frames and optics figures."""

from typing import Any, Dict, Optional, Tuple

import numpy as np
import numpy.typing as npt

def camera_model(objective: str = "20x") -> Dict[str, Any]: ...
def render(scene: str = "pick-place",
           objective: str = "20x",
           focus_um: float = 0.0,
           exposure_ms: Optional[float] = None,
           gain: Optional[float] = None,
           bit_depth: int = 12,
           illumination: str = "reflected",
           seed: int = 1,
           frame: int = 0,
           tool_um: Optional[Tuple[float, float, float]] = None) -> npt.NDArray[Any]: ...
