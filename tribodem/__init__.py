"""tribodem: wear at contact interfaces with particles.

Rooms: ``dem`` (particle engine), ``io`` (configs, results, VTK, the run record),
``cyclejump`` (cycle-jumping strategies), ``materials``, and the applications built on
them. Each command is a function too, e.g. ``tribodem.dem.run(config, out)`` and
``tribodem.materials.calibrate(material, out)``, returning a
:class:`tribodem.io.record.RunResult`. ``python -m tribodem`` is the ``tribodem`` command.

Nothing is imported here (``import tribodem.dem`` loads the engine), so the command starts
fast and any room may read :data:`__version__`.
"""

__version__ = "0.1.0"
