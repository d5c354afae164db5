"""Peers of the cell problems: the statistical mixed-lubrication model (Patir-Cheng average
flow factors, Greenwood-Tripp contact) as :class:`~fem_twin.micro.FlowFactors`.

``average_flow_factors(pin, disk, e_reduced)`` -> FlowFactors the macro scale takes as it
is; :mod:`.patir_cheng` the published fits, :mod:`.greenwood_tripp` the contact.
"""

from .average_flow import PairStatistics, average_flow_factors, mean_gap
from .greenwood_tripp import Summits, contact_fraction, contact_pressure, tail_moment

__all__ = ["PairStatistics", "average_flow_factors", "mean_gap", "Summits",
           "contact_fraction", "contact_pressure", "tail_moment"]
