"""The laws of the macro scale: what the lubricant, the contacts and the disk do.

The film solver (:mod:`fem_twin.macro.film`), the coupled point
(:mod:`fem_twin.macro.coupling`) and the references (:mod:`fem_twin.macro.reference`) read
them; they import nothing else of ``macro/``.

    lubricant          Roelands piezoviscosity (eq 23) and Dowson-Higginson density (eq 24)
    viscosity          viscosity against temperature: the Walther equation of ASTM D341
    friction           the film's shear on the pin and on the disk (eqs 31, 33-34)
    boundary_laws      the boundary laws (eq 32, the shear law) and their registry
    boundary_friction  the [boundary] section and the asperities' shear at the nodes
    thermal            the contact's temperature from its own frictional heat
    kinematics         the disk's velocity over the pin face, u = omega x r
"""

from .boundary_friction import BoundaryLaw, boundary_traction
from .friction import FilmFields, confined_shear, disk_shear, eyring_shear, hydrodynamic_shear
from .kinematics import disk_velocity, in_grid_frame
from .lubricant import Lubricant
from .thermal import ContactThermal, ThermalNotConverged, ThermalSettings, thermal_point
from .viscosity import WaltherLaw

__all__ = ["BoundaryLaw", "boundary_traction",
           "FilmFields", "confined_shear", "disk_shear", "eyring_shear", "hydrodynamic_shear",
           "disk_velocity", "in_grid_frame",
           "Lubricant",
           "ContactThermal", "ThermalNotConverged", "ThermalSettings", "thermal_point",
           "WaltherLaw"]
