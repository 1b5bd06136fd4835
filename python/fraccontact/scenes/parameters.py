"""The scenes' parameters, each with its source or the rule it is derived by.

"published" values are quoted from the source named; "derived" ones follow
from published values by the rule given (computed in this module, not
typed in); "assumed" ones are representative values for which the sources
searched (Euro NCAP and UN GTR 9 texts, BASt and NHTSA bonnet studies,
Anderson & Searson 2008, Hutchinson 2013 and 2011, SAE low-speed bumper
papers) give no number: the scenes' figures depend on them, and
docs/scenes_reference.md shows how much.

Pedestrian headform on a bonnet

| quantity | value | kind | source / rule |
|---|---|---|---|
| adult headform mass, speed | 4.5 kg, 11.1 m/s | published | Euro NCAP pedestrian protocol (40 km/h) |
| child headform mass, speed | 3.5 kg, 9.7 m/s | published | UN GTR 9 headform tests (35 km/h) |
| HIC15 limits | 1000, 1700 | published | UN GTR 9 (1000 over most of the bonnet test area, 1700 over the rest) |
| certification drop | 376 mm (14.8 in) onto a rigid plate, 225-275 g | published | 49 CFR 572.32(b) (Hybrid III head; the pedestrian headform's drop test uses the same height and corridor) |
| skin k (Hertz, n = 3/2) | 4.79e7 N/m^1.5 | derived | the elastic Hertz impact of the 4.5 kg headform from 376 mm peaks at 250 g, the corridor's middle (hertz.stiffness_for_peak) |
| skin c | 2.70e4 N s/m | derived | restitution SKIN_RESTITUTION (assumed 0.8) in that drop with that k |
| panel effective mass m_p | 0.345 kg | assumed | the bonnet within 100 mm of the impact point (the head's radius is 82.5 mm) sets off first: pi (0.1 m)^2 x two 0.7 mm steel sheets (outer and inner panel, 7850 kg/m^3) |
| panel bending stiffness k_p | 5e4 N/m (50 N/mm) | assumed | the bonnet's stiffness to a point load at mid-span |
| panel damping c_p | 300 N s/m | assumed | damping ratio 0.3 with the adult head and panel |
| hard point k (Hertz) | 1.24e10 N/m^1.5 | derived | k = (4/3) E* sqrt(R): steel panel (210 GPa, 0.3) on an aluminium part (70 GPa, 0.33) of radius 25 mm (assumed) |
| hard point c | 1e5 N s/m | assumed | stiff: the dashpot yields little at the panel's speed |
| clearance found needed | about 50 mm child, 70 mm adult | published | BASt bonnet study, the comparison for clearance_for_hic |

Low-speed bumper impact

| quantity | value | kind | source / rule |
|---|---|---|---|
| impact speed | 2.5 mph = 1.1176 m/s | published | 49 CFR 581 (bumper standard) |
| impact speed | 4 km/h = 1.1111 m/s | published | UN ECE R42 |
| vehicle body mass M | 1500 kg | assumed | a mid-size car (about 1 500 kg) |
| bumper beam + fascia mass m_b | 5 kg | assumed | |
| crash box stiffness k_box | 1e6 N/m (1 kN/mm) | assumed | elastic at these speeds (49 CFR 581: no damage) |
| crash box damping c_box | 7.75e3 N s/m | assumed | damping ratio 0.1 of the body on the crash box |
| fascia k (Hertz) | 2.92e9 N/m^1.5 | derived | k = (4/3) E* sqrt(R): polypropylene (2.64 GPa, 0.4: docs/model.md §1, the paper's h20 fit) against a steel barrier (210 GPa, 0.3), fascia radius of curvature 0.5 m (assumed) |
| fascia c | 5.19e4 N s/m | derived | restitution 0.59 (the paper's h20, docs/model.md §1) of the beam alone striking the barrier at 2.5 mph with that k |
| vehicle-to-vehicle restitution | 0.2-0.4 at 2-5 mph | published | Howard, Bomar & Bare, SAE 931842, the comparison for the bumper's restitution |

Elastic Hertz limit: HIC ~ m^(-3/(2(n+1))) v^((4n+1)/(n+1)), i.e. m^-0.6 v^2.8 at
n = 3/2 (Hutchinson, J Biomech Eng 135 (2013) 114508).
"""

import functools
import math
from dataclasses import dataclass

from .. import hertz
from ..crash import STANDARD_GRAVITY
from . import chain


@dataclass(frozen=True)
class Headform:
    name: str
    m: float   # kg
    v: float   # m/s


ADULT = Headform("adult", 4.5, 11.1)
CHILD = Headform("child", 3.5, 9.7)
HIC_LIMITS = (1000.0, 1700.0)

CERTIFICATION_DROP = 0.376     # m
CERTIFICATION_PEAK_G = 250.0   # the middle of 225-275 g
SKIN_RESTITUTION = 0.8         # assumed

STEEL = (210e9, 0.3)
ALUMINIUM = (70e9, 0.33)
POLYPROPYLENE = (2.64e9, 0.4)
FASCIA_RESTITUTION = 0.59      # the paper's h20 drop test


@dataclass(frozen=True)
class Bonnet:
    m_p: float = math.pi * 0.1 ** 2 * 2 * 7850.0 * 0.7e-3   # kg
    k_p: float = 5e4           # N/m
    c_p: float = 300.0         # N s/m
    R_hard: float = 0.025      # m, the hard point's radius
    c_hard: float = 1e5        # N s/m

    @property
    def k_hard(self):
        return hertz.k_from_materials(self.R_hard, *STEEL, *ALUMINIUM)


@dataclass(frozen=True)
class Bumper:
    M: float = 1500.0          # kg
    m_b: float = 5.0           # kg
    k_box: float = 1e6         # N/m
    zeta_box: float = 0.1      # damping ratio of M on k_box
    R_fascia: float = 0.5      # m

    @property
    def c_box(self):
        return 2.0 * self.zeta_box * math.sqrt(self.k_box * self.M)

    @property
    def k_fascia(self):
        return hertz.k_from_materials(self.R_fascia, *STEEL, *POLYPROPYLENE)


SPEEDS = {"49 CFR 581": 2.5 * 0.44704, "ECE R42": 4.0 / 3.6}


def certification_speed():
    """sqrt(2 g h) of the certification drop [m/s]."""
    return math.sqrt(2.0 * STANDARD_GRAVITY * CERTIFICATION_DROP)


@functools.cache
def skin():
    """(k, c) of the headform's skin: k gives the 4.5 kg headform's elastic
    certification drop its corridor's middle peak, c its assumed restitution."""
    v = certification_speed()
    k = hertz.stiffness_for_peak(ADULT.m * CERTIFICATION_PEAK_G * STANDARD_GRAVITY, ADULT.m, v)
    return k, chain.dashpot_for_restitution(SKIN_RESTITUTION, k, ADULT.m, v)


@functools.cache
def fascia(bumper=Bumper()):
    """(k, c) of the fascia: k from the materials, c giving the beam alone the
    material's drop-test restitution at 49 CFR 581's speed."""
    k = bumper.k_fascia
    return k, chain.dashpot_for_restitution(FASCIA_RESTITUTION, k, bumper.m_b, SPEEDS["49 CFR 581"])
