"""tribodem: wear at contact interfaces with particles.

Rooms: ``dem`` (particle engine), ``io`` (configs, results, VTK), ``cyclejump``
(cycle-jumping strategies), and the applications built on them.
"""

__version__ = "0.1.0"
