"""The twin's numeric kernels, as the diagnosis takes them: pass this module as
``backend`` to the diagnosis (:func:`lugre.diagnosis.diagnose`,
:func:`lugre.diagnosis.evaluate`, :func:`lugre.diagnosis.residual.prepare` ...) for the
NumPy twins of what :mod:`lugre._native`, the default, takes from the Rust core.

The diagnosis reads ``InverseRecord`` (the inverse-dynamics kernel over a prepared
record), ``simulate``, ``position_sums`` and ``irls_linear_grid``; the rest are here so
that the two kernel modules offer the same names.
"""

from __future__ import annotations

from .coupling import load_coupling
from .friction import friction_force, stribeck
from .inverse import InverseRecord, filtfilt, moving_median, position_sums
from .linear import irls_linear, irls_linear_grid
from .servo import simulate, simulate_batch

__all__ = ["InverseRecord", "filtfilt", "friction_force", "irls_linear", "irls_linear_grid",
           "load_coupling", "moving_median", "position_sums", "simulate", "simulate_batch", "stribeck"]
