"""Pure numerical core of viscoadh_ros: no ROS imports (numpy, numba, scipy, yaml only).

Modules are named after the one concept they hold: ``profiles`` (indenters and their MDR
profiles), ``rheology`` (the creep element and Prony conversion), ``criterion`` (energy
criterion and scale separation), ``reference`` (closed-form solutions), ``config`` (the scene
schema and loader), ``simulator``/``history`` (the stepping model).
"""

from viscoadh_ros.core.errors import ConfigError, InputError

__all__ = ["ConfigError", "InputError"]
