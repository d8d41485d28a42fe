"""Identification of the stick-slip axis (thesis §2.5.2) from arrays (t [s], u [V], x [m]) or files."""

import os
from typing import Any, Dict, Optional, Sequence, Union

import numpy.typing as npt

TOrFile = Union[npt.ArrayLike, str, os.PathLike]
Params = Union[None, Dict[str, Any], str, os.PathLike]

def record(t: TOrFile, u: Optional[npt.ArrayLike] = None, x: Optional[npt.ArrayLike] = None) -> Dict[str, Any]: ...
def pe_modes(t: TOrFile, u: Optional[npt.ArrayLike] = None, x: Optional[npt.ArrayLike] = None,
             params: Params = None) -> Dict[str, Any]: ...
def friction_modes(t: TOrFile, u: Optional[npt.ArrayLike] = None, x: Optional[npt.ArrayLike] = None,
                   params: Params = None) -> Dict[str, Any]: ...
def hysteresis(t: TOrFile, u: Optional[npt.ArrayLike] = None, x: Optional[npt.ArrayLike] = None,
               operators: int = 35, params: Params = None) -> Dict[str, Any]:
    """Step 2: 'pi', 'inverse', 'static_gain_m_V', 'rms_m', 'first_fitted', 'from_rest' (decided by
    fitting both hypotheses over the whole record), 'rms_from_rest_m' / 'rms_steady_loop_m' (None
    when the record does not start near its lowest voltage), 'voltage_noise_V', 'fitted_m'."""
# A record: a file name, or {'t': [s], 'u': [V], 'x': [m]} arrays. A sawtooth run adds
# 'amplitude_V', 'frequency_Hz' and 'direction' ('forward' | 'backward') to such a dict.
Record = Union[str, os.PathLike, Dict[str, Any]]
Runs = Union[str, os.PathLike, Sequence[Dict[str, Any]]]

def breakaway(runs: Runs, params: Params = None, threads: int = 0) -> Dict[str, Any]:
    """Step 3: z_ba per run and the table; runs: a directory of sawtooth_*.csv or a list of run dicts.
    'filled': cells interpolated between fitted ones; 'extrapolated': cells beyond them (runs below
    the stepping threshold), from the line of their frequency's fitted cells."""
def all(records: Union[str, os.PathLike, Dict[str, Any]], params: Params = None,
        operators: int = 35) -> Dict[str, Any]:
    """Steps 1-3: a directory, or {'pe_step' (optional), 'step', 'sine': Record, 'sawtooth': Runs}."""
