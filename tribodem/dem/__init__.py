"""tribodem.dem: the particle engine (2D disks with thickness, 3D spheres).

Rooms, one concept each (JAX-MD style: plain kernels over arrays, small classes that
wire them): ``state`` (particle arrays), ``space`` (box, periodic axes),
``neighbors`` (cell-list Verlet lists), ``laws`` (contact laws as styles: one module
each, ``laws.register`` adds one), ``contact`` (materials, pair table, the shared contact
response and pair kernel), ``walls`` (planes, their own force pass over a near-wall list,
servo walls), ``integrate`` (central difference with damping, time-step estimates),
``engine`` (``Simulation``: the step loop, checkpoints), ``recorders`` (CSV, VTK),
``bonds`` (linear parallel bonds, breakage log), ``thermal`` (temperature, expansion,
conduction through intact bonds), ``clumps`` (rigid multi-sphere debris bodies),
``trimesh`` (rigid triangle-mesh surfaces, e.g. from STL).

From Python, :func:`run` is ``tribodem dem run`` (``demo``: the settling / compression
demo, config :class:`DemRunConfig` in ``config``), returning a
:class:`~tribodem.io.record.RunResult`; ``bench`` measures throughput (``tribodem bench
dem``).
"""

from tribodem.dem import laws
from tribodem.dem.bonds import BondBreak, ParallelBonds, install_bonds_by_gap
from tribodem.dem.clumps import Clumps, ClumpTemplate, debris_template, make_clumps
from tribodem.dem.config import DemRunConfig
from tribodem.dem.contact import Material
from tribodem.dem.demo import run
from tribodem.dem.engine import Simulation
from tribodem.dem.errors import SimulationUnstable, TimeStepError
from tribodem.dem.space import Box
from tribodem.dem.state import ParticleState
from tribodem.dem.thermal import Thermal
from tribodem.dem.trimesh import TriangleSurface
from tribodem.dem.walls import PlaneWall

__all__ = [
    "BondBreak",
    "Box",
    "ClumpTemplate",
    "Clumps",
    "DemRunConfig",
    "Material",
    "ParallelBonds",
    "ParticleState",
    "PlaneWall",
    "Simulation",
    "SimulationUnstable",
    "Thermal",
    "TimeStepError",
    "TriangleSurface",
    "debris_template",
    "install_bonds_by_gap",
    "laws",
    "make_clumps",
    "run",
]
