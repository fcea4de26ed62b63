"""Classic constrained and rolling systems from outside the two books, as problem files
with answer keys derived here (each derivation in the docstring of its constant), for
tests/test_manifold.py and tests/test_rolling.py."""

from __future__ import annotations

from pathlib import Path

from mechbook.engine.analysis import Analysis
from mechbook.model.problem import load_problem
from mechbook.records import Outcome
from mechbook.verify.answers import load_answers
from mechbook.verify.checker import check_problem


def write_tree(tmp_path: Path, num: str, problem: str, answers: str) -> tuple[Path, Path]:
    """Problem and answer files lim-<num> in a tree under tmp_path."""
    for kind, text in (("problems", problem), ("answers", answers)):
        d = tmp_path / kind / "lim"
        d.mkdir(parents=True, exist_ok=True)
        (d / f"{num}.yaml").write_text(text.replace("NUM", num))
    return (tmp_path / "problems" / "lim" / f"{num}.yaml",
            tmp_path / "answers" / "lim" / f"{num}.yaml")


def check(tmp_path: Path, num: str, problem: str, answers: str) -> dict[str, Outcome]:
    """Every part's outcome, by part name."""
    ppath, apath = write_tree(tmp_path, num, problem, answers)
    outcomes = check_problem(Analysis(load_problem(ppath)), load_answers(apath))
    return {o.part: o for o in outcomes}


def key(parts: str) -> str:
    return f"problem: lim-NUM\nsource: derived in tests/constrained_systems.py\nparts:\n{parts}"


# A particle held on a circle of radius l by the multiplier constraint x² + y² = l², in
# gravity. Its energy E = m(ẋ² + ẏ²)/2 + m g y is conserved along every motion on the
# circle (the constraint force is normal to the velocity there); off the circle the engine's
# accelerations are not a motion at all. One freedom: 2 coordinates less 1 constraint.
# Small oscillations about the bottom (0, −l): ω² = g/l.
CIRCLE = """\
id: lim-NUM
source: a particle on a circle, by a multiplier
title: particle on a circle (x, y, one constraint)
parameters:
  m: {value: 0.5}
  l: {value: 1.3}
  g: {}
coordinates:
  x: {}
  y: {}
particles:
  bob: {mass: m, position: [x, y]}
gravity: {}
constraints:
  - {name: rod, expr: "x**2 + y**2 - l**2"}
"""

# A spherical pendulum in Cartesian coordinates: three coordinates, one constraint
# x² + y² + z² = l²: two freedoms. About the bottom (0, 0, −l) both modes have ω² = g/l.
SPHERICAL = """\
id: lim-NUM
source: a spherical pendulum in x, y, z
title: spherical pendulum, Cartesian, one multiplier
parameters:
  m: {value: 0.7}
  l: {value: 0.9}
  g: {}
coordinates:
  x: {}
  y: {}
  z: {}
particles:
  bob: {mass: m, position: [x, y, z]}
gravity: {}
constraints:
  - {name: rod, expr: "x**2 + y**2 + z**2 - l**2"}
"""

# sympy.physics.mechanics' rolling disc (tests/test_linearize.py, Kane's method): yaw q1
# about the vertical, lean q2, spin q3 about the disc's axis (its own y), centre (q4, q5) and
# height −r cos q2 with z pointing down; I = m r²/4 about a diameter, J = m r²/2 about the
# axis; the contact point is the centre plus r along the lean frame's z.
SYMPY_DISC = """\
id: lim-NUM
source: sympy.physics.mechanics, test_linearize.py, rolling disc
title: thin disc rolling on a plane, in sympy's coordinates
parameters:
  m: {}
  r: {}
  g: {}
  Omega: {doc: spin rate of straight rolling, value: 2.0}
  phi0: {doc: heading, positive: false, value: 0.3}
coordinates:
  q1: {doc: yaw}
  q2: {doc: lean}
  q3: {doc: spin}
  q4: {doc: x of the centre}
  q5: {doc: y of the centre}
rigid_bodies:
  disc:
    mass: m
    position: [q4, q5, -r*cos(q2)]
    inertia: [[m*r**2/4, 0, 0], [0, m*r**2/2, 0], [0, 0, m*r**2/4]]
    rotation: [[z, q1], [x, q2], [y, q3]]
gravity: {up: [0, 0, -1]}
rolling:
  - name: contact
    body: disc
    point: [q4 + r*sin(q1)*sin(q2), q5 - r*cos(q1)*sin(q2), 0]
"""

# A coin (uniform disk, or a hoop) rolling on a horizontal plane, in z-x-z Euler angles:
# heading phi, tilt theta of its axis from the vertical (upright: theta = pi/2), spin psi;
# centre (x, y, R sin theta) - the rim's lowest point touches z = 0. The contact point comes
# from the declared shape.
#
# Upright straight rolling with spin rate Ω (ψ̇ = Ω, θ = π/2, φ̇ = 0) is a steady motion.
# Small tilt δθ and heading rate δφ̇ (Newton–Euler about the centre, to first order; the
# contact force's torque about the vertical is second order, so the vertical angular
# momentum I1 φ̇ + I3 Ω cos θ is conserved to first order):
#   I1 δφ̈ = I3 Ω δθ̇                                         (heading)
#   (I1 + m R²) δθ̈ = −m g R δθ + (I3 + m R²) Ω δφ̇ ... with δφ̇ = I3 Ω δθ / I1 + const:
#   (I1 + m R²) δθ̈ = −[I3 (I3 + m R²) Ω²/I1 − m g R] δθ  (signs for the tilt measured so
#   that gravity topples it), so the wobble frequency is
#   ω² = [I3 (I3 + m R²) Ω²/I1 − m g R] / (I1 + m R²)
# and upright rolling is stable exactly where ω² > 0: Ω² > m g R I1 / (I3 (I3 + m R²)).
# Uniform disk (I1 = m R²/4, I3 = m R²/2): Ω² > g/(3R), ω² = (12 Ω² − 4 g/R)/5 — the same
# as sympy's A matrix gives (u1' = 4/5 q2 + 6/5 q3d u3, u3' = −2 q3d u1 at m = r = g = 1).
# Hoop (I1 = m R²/2, I3 = m R²): Ω² > g/(4R), ω² = [4 m R² Ω² − m g R]/(3 m R²/2)
# = (8 Ω² − 2 g/R)/3.
COIN = """\
id: lim-NUM
source: a rolling coin, Euler angles
title: coin rolling on a plane
parameters:
  m: {value: 0.4}
  R: {value: 0.3}
  g: {}
  Omega: {doc: spin rate, value: 5.0}
coordinates:
  x: {}
  y: {}
  phi: {doc: heading}
  theta: {doc: tilt of the axis from the vertical, range: [0, pi]}
  psi: {doc: spin}
rigid_bodies:
  coin:
    mass: m
    position: [x, y, R*sin(theta)]
    inertia: {shape: SHAPE, radius: R}
    euler_angles: [phi, theta, psi]
gravity: {}
rolling:
  - {name: contact, body: coin}
"""

# The Chaplygin sleigh: a body on a plane with a knife edge at C = (x, y) along its axis
# (heading theta), its centre of mass a ahead of C, moment I about the centre of mass. The
# blade does not slide sideways: −ẋ sin θ + ẏ cos θ = 0. With u the speed of C along the
# axis and ω = θ̇, Newton–Euler (the blade's force is sideways, at C) give
#   m u̇ = m a ω²,   (I + m a²) ω̇ = −m a u ω,
# so straight motion at speed v (u = v, ω = 0) has exponents 0 (heading), 0 (speed) and
# −m a v/(I + m a²) (the turning rate decays when a v > 0: the centre of mass ahead of the
# blade in the direction of motion; it grows when a v < 0: the sleigh turns round).
SLEIGH = """\
id: lim-NUM
source: the Chaplygin sleigh
title: Chaplygin sleigh (a knife edge)
parameters:
  m: {value: 1.5}
  I: {value: 0.2}
  a: {value: 0.4, positive: false}
  v: {value: 1.2, positive: false}
coordinates:
  x: {}
  y: {}
  theta: {}
rigid_bodies:
  sled:
    mass: m
    position: [x + a*cos(theta), y + a*sin(theta)]
    inertia: I
    angular_velocity: thetadot
velocity_constraints:
  - {name: blade, expr: "-xdot*sin(theta) + ydot*cos(theta)"}
"""

# A uniform ball (I = 2 m R²/5) rolling on a turntable that turns at Ω about the vertical
# through the origin. With the centre at (x, y, R) and the table's velocity Ω ẑ × P at the
# contact P, the no-slip condition v_G + ω × (−R ẑ) = Ω ẑ × P and Euler's equation about the
# contact give r̈ = (I/(I + m R²)) Ω ẑ × ṙ = (2/7) Ω ẑ × ṙ: the centre moves on circles at
# angular frequency 2Ω/7 (any radius, any centre), whatever the ball's spin. The ball's
# attitude: rotations about space-fixed x, y then its own z (regular at the identity).
TURNTABLE = """\
id: lim-NUM
source: a ball on a turntable
title: ball rolling on a turntable
parameters:
  m: {value: 0.3}
  R: {value: 0.05}
  g: {}
  Omega: {doc: the table's rate, value: 3.0}
coordinates:
  x: {}
  y: {}
  a: {}
  b: {}
  c: {}
rigid_bodies:
  ball:
    mass: m
    position: [x, y, R]
    inertia: {shape: solid_sphere, radius: R}
    rotation: [[x, a], [y, b], [z, c]]
gravity: {}
rolling:
  - name: contact
    body: ball
    surface: {normal: [0, 0, 1], velocity: ["-Omega*y", "Omega*x", 0]}
"""

# A hoop (mass m, radius R) rolling without slipping down a plane inclined at alpha: x
# along the slope (down), phi its turn. Rolling: ẋ = R φ̇ (the contact's velocity, centre's
# less R φ̇ along the slope, vanishes). Newton: m ẍ = m g sin α − F, m R² φ̈ = F R, so
# ẍ = g sin α / 2 and the friction that rolling needs is F = m g sin α / 2, up the slope.
# In the frame of the slope, gravity points along (sin α, −cos α).
HOOP = """\
id: lim-NUM
source: a hoop rolling down an incline
title: hoop rolling down an incline
parameters:
  m: {value: 0.8}
  R: {value: 0.25}
  g: {}
  alpha: {value: 0.4}
coordinates:
  x: {doc: distance travelled down the slope}
  phi: {doc: turn of the hoop}
rigid_bodies:
  hoop:
    mass: m
    position: [x, R]
    inertia: {shape: ring, radius: R}
    angular_velocity: -phidot
gravity: {up: [-sin(alpha), cos(alpha)]}
rolling:
  - {name: contact, body: hoop}
"""

# sympy.physics.mechanics' rolling disc by Lagrange's method (test_linearize.py): the disc's
# centre moves as if it turned about the contact point C held fixed, v = ω × (r L.z), so T
# is not a function of a position alone; sympy's own kinetic energy of that model (BodyD,
# printed by sympy.physics.mechanics and copied here), and its potential −m g r cos q2.
SYMPY_LAGRANGE_DISC = """\
id: lim-NUM
source: sympy.physics.mechanics, test_linearize.py, rolling disc (Lagrange)
title: sympy's rolling disc by Lagrange's method
parameters:
  m: {}
  r: {}
  g: {}
  Omega: {doc: spin rate, value: 2.0}
coordinates:
  q1: {}
  q2: {}
  q3: {}
kinetic: "m*r**2*(5*q1dot**2*sin(q2)**2 + q1dot**2 + 12*q1dot*q3dot*sin(q2)
  + 5*q2dot**2 + 6*q3dot**2)/8"
potential: "-m*g*r*cos(q2)"
"""

# A uniform ball (radius r, I = 2 m r²/5) rolling inside a spherical bowl of radius Rb: its
# centre (x, y, z) on the sphere of radius Rb − r about the bowl's centre (the origin),
# z = −sqrt((Rb − r)² − x² − y²); the contact point on the same ray, at distance Rb. A
# curved surface: the contact point is stated, and the fixed normal (the bowl's axis) is
# nowhere perpendicular to the true one over the bowl's lower half, so the two tangential
# rows and the kept contact make the contact point's velocity vanish. Small oscillations
# about the bottom: the centre moves on a sphere of radius Rb − r with rolling,
# (m + I/r²)(Rb − r) θ̈ = −m g θ, ω² = (5/7) g/(Rb − r), twice (both directions).
BOWL = """\
id: lim-NUM
source: a ball rolling in a spherical bowl
title: ball in a bowl
parameters:
  m: {value: 0.2}
  r: {value: 0.1}
  Rb: {value: 1.0}
  g: {}
conditions: ["Rb > r"]
coordinates:
  x: {}
  y: {}
  a: {}
  b: {}
  c: {}
rigid_bodies:
  ball:
    mass: m
    position: [x, y, "-sqrt((Rb - r)**2 - x**2 - y**2)"]
    inertia: {shape: solid_sphere, radius: r}
    rotation: [[x, a], [y, b], [z, c]]
gravity: {}
rolling:
  - name: contact
    body: ball
    point: ["x*Rb/(Rb - r)", "y*Rb/(Rb - r)", "-sqrt((Rb - r)**2 - x**2 - y**2)*Rb/(Rb - r)"]
"""
