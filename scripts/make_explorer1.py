#!/usr/bin/python3
"""Writes the Explorer I models with physical whip antennas (docs/explorer1.md):

  models/explorer1.yaml         four steel whips as built-in Euler-Bernoulli beams
                                (foreshortening on: centrifugal stiffening), modal damping
  models/explorer1_hinged.yaml  the same spacecraft with each whip a rigid rod on a flap
                                hinge whose spring and damper give the whip's first mode
                                (the rigid-hinge twin of the seed paper's Fig. 6)

Every number and its source is written into the model files' header comments.
Usage: make_explorer1.py [--diameter-mm D] [--zeta Z] [--seed-deg A] [--out-dir DIR] [--suffix S]
(the defaults write the two committed models).
"""
import argparse
import math
import os

# ---- documented data (sources: docs/explorer1.md, "Data and sources") ----
MASS_TOTAL = 13.97          # kg in orbit, instrument section + empty 4th-stage motor case (NASA/JPL, Wikipedia)
LENGTH = 2.03               # m (80 in)
RADIUS = 0.076              # m (6.00 in diameter / 2)
SPIN_RPM = 750.0            # rpm about the long axis at injection (Wikipedia; Bollay: "about 10 rev/s")
WHIP_LENGTH = 0.56          # m (22 in; Levinson/Roithmayr data in the PyDy Explorer example)
WHIP_STATION = 0.10         # m from the centre of mass along the long axis ("from the middle of the satellite")
# material: spring steel (handbook): E, G, rho
E_STEEL, G_STEEL, RHO_STEEL = 200e9, 79e9, 7850.0


def whip(d_mm):
    d = d_mm * 1e-3
    mu = RHO_STEEL * math.pi * d * d / 4
    EI = E_STEEL * math.pi * d ** 4 / 64
    GJ = G_STEEL * math.pi * d ** 4 / 32
    return mu, EI, GJ


def header_common(args, mu, EI, GJ, m_whip, bus_mass, Ixx, Izz, spin, wx, Is, It):
    f1 = 1.8751040687 ** 2 / (2 * math.pi * WHIP_LENGTH ** 2) * math.sqrt(EI / mu)
    return f"""#
# Data (docs/explorer1.md gives every source):
#   spacecraft mass in orbit {MASS_TOTAL} kg (instruments and the empty fourth-stage motor case,
#     which stayed attached), length {LENGTH} m (80 in), diameter {2 * RADIUS} m (6 in);
#   spin about the long axis {SPIN_RPM:g} rpm = {spin:.6g} rad/s at injection;
#   four whip antennas (the 108.00 MHz turnstile), {WHIP_LENGTH} m (22 in) each, radial at 90 deg,
#     at the skin (r = {RADIUS} m), {WHIP_STATION} m from the centre of mass along the long axis.
# Not published (what was chosen, and the range tried, docs/explorer1.md):
#   whip material and diameter: spring-steel wire, d = {args.diameter_mm:g} mm (tried 1.0 to 3.0 mm):
#     mu = rho pi d^2/4 = {mu:.6g} kg/m (m = {m_whip * 1e3:.4g} g each), EI = E pi d^4/64 = {EI:.6g} N m^2
#     (both planes), GJ = G pi d^4/32 = {GJ:.6g} N m^2 (torsion: ~1.4 kHz, not kept);
#     first bending frequency at rest f1 = {f1:.4g} Hz;
#   structural damping ratio zeta = {args.zeta:g} (tried 0.005 to 0.05; no measured value exists);
#   mass distribution: the bus is a uniform solid cylinder of the remaining mass
#     {bus_mass:.6g} kg: Izz = m r^2/2 = {Izz:.7g}, Ixx = Iyy = m (3 r^2 + L^2)/12 = {Ixx:.7g} kg m^2;
#   initial nutation: {args.seed_deg:g} deg (wx = {wx:.6g} rad/s; the injection value is not known; the
#     transition time grows with its logarithm).
# Whole spacecraft (rigid, antennas straight): I_spin = {Is:.6g}, I_transverse = {It:.6g} kg m^2.
"""


def spacecraft(args):
    mu, EI, GJ = whip(args.diameter_mm)
    m_whip = mu * WHIP_LENGTH
    bus_mass = MASS_TOTAL - 4 * m_whip
    Izz = bus_mass * RADIUS ** 2 / 2
    Ixx = bus_mass * (3 * RADIUS ** 2 + LENGTH ** 2) / 12
    spin = SPIN_RPM * 2 * math.pi / 60
    # whole-spacecraft inertias with straight whips (rods, com at the middle)
    r_mid = RADIUS + WHIP_LENGTH / 2
    rod = m_whip * WHIP_LENGTH ** 2 / 12
    Is = Izz + 4 * (rod + m_whip * r_mid ** 2)
    It = Ixx + 2 * (rod + m_whip * r_mid ** 2) + 4 * m_whip * WHIP_STATION ** 2
    wx = math.tan(math.radians(args.seed_deg)) * Is * spin / It
    return dict(mu=mu, EI=EI, GJ=GJ, m_whip=m_whip, bus_mass=bus_mass, Izz=Izz, Ixx=Ixx, spin=spin, wx=wx, Is=Is,
                It=It)


def bodies(s, whip_body):
    out = f"""bodies:
  - name: bus
    parent: ground
    joint: {{type: free}}
    mass: {s['bus_mass']:.10g}
    com: [0, 0, 0]
    inertia: [{s['Ixx']:.10g}, {s['Ixx']:.10g}, {s['Izz']:.10g}, 0, 0, 0]
"""
    for k, phi in enumerate([0, 90, 180, 270]):
        c, sn = math.cos(math.radians(phi)), math.sin(math.radians(phi))
        x, y = RADIUS * c, RADIUS * sn
        out += whip_body(k + 1, x, y, math.radians(phi))
    return out


def flexible_model(args):
    s = spacecraft(args)
    zeta = args.zeta

    def whip_body(k, x, y, yaw):
        return f"""  - name: ant{k}
    parent: bus
    joint: {{type: fixed, position: [{x:.12g}, {y:.12g}, {WHIP_STATION}], rotation: {{rpy: [0, 0, {yaw:.17g}]}}}}
    flexible:
      beam: {{length: {WHIP_LENGTH}, direction: x, mass_per_length: {s['mu']:.10g}, EI: [{s['EI']:.10g}, {s['EI']:.10g}],
             elements: {args.elements}, modes: 2}}
      damping_ratio: {zeta:g}
      foreshortening: true
"""
    name = "explorer1" + args.suffix
    text = f"""# {name}: Explorer I with physical whip antennas: four spring-steel wires as built-in
# Euler-Bernoulli cantilevers with foreshortening (so spin stiffens them, exactly), ordinary
# structural damping. Written by scripts/make_explorer1.py (edit that, not this file).
#
# The story (Bracewell & Garriott 1958; Bollay, Stanford ECL 1006): Explorer I spun about its
# long axis, its axis of MINIMUM inertia; energy dissipated in its flexing whips let the
# nutation grow until, within about one orbit (115 min), it tumbled about a transverse axis of
# maximum inertia with the same angular momentum.
""" + header_common(args, s['mu'], s['EI'], s['GJ'], s['m_whip'], s['bus_mass'], s['Ixx'], s['Izz'], s['spin'],
                    s['wx'], s['Is'], s['It']) + f"""# Each whip: {args.elements} elements, the 2 lowest modes (flap along the long axis and lead-lag in
# the spin plane: equal EI, so one pair), fixed at the skin with its joint-frame x radial.
# Run: see docs/explorer1.md (scripts/explorer1_study.py makes that page).
name: {name}
description: Explorer I, rigid bus spinning about its minor axis, four spring-steel whip antennas as flexible beams with foreshortening and structural damping
gravity: [0, 0, 0]

""" + bodies(s, whip_body) + f"""
initial:
  u: {{bus.wz: {s['spin']:.17g}, bus.wx: {s['wx']:.17g}}}

outputs: [energy, momentum]
"""
    return name, text


def hinged_model(args):
    s = spacecraft(args)
    m, l = s['m_whip'], WHIP_LENGTH
    I_h = m * l * l / 3                     # rod about its root
    w0 = 1.8751040687 ** 2 / (l * l) * math.sqrt(s['EI'] / s['mu'])  # the whip's first mode at rest
    k = w0 * w0 * I_h
    c = 2 * args.zeta * w0 * I_h

    def whip_body(kk, x, y, yaw):
        return f"""  - name: ant{kk}
    parent: bus
    joint: {{type: revolute, axis: [0, 1, 0], position: [{x:.12g}, {y:.12g}, {WHIP_STATION}], rotation: {{rpy: [0, 0, {yaw:.17g}]}}, stiffness: {k:.10g}, damping: {c:.10g}}}
    mass: {m:.10g}
    com: [{l / 2}, 0, 0]
    inertia: [{m * 1e-8:.6g}, {m * l * l / 12:.10g}, {m * l * l / 12:.10g}, 0, 0, 0]
"""
    name = "explorer1_hinged" + args.suffix
    text = f"""# {name}: the rigid-hinge twin of explorer1{args.suffix}.yaml (the seed paper's Fig. 6
# comparison): each whip a rigid rod of the same mass on a flap hinge at the skin (axis
# tangential: it flaps along the long axis), with a spring and a damper that give the rod
# the whip's first bending frequency at rest and the same damping ratio:
#   I_h = m l^2/3 = {I_h:.6g} kg m^2, w0 = 1.8751^2/l^2 sqrt(EI/mu) = {w0:.6g} rad/s,
#   k = w0^2 I_h = {k:.6g} N m/rad, c = 2 zeta w0 I_h = {c:.6g} N m s/rad.
# Centrifugal stiffening of a hinged rod is exact by construction (Omega^2 I_h (1 + 3 r/(2 l))).
# Written by scripts/make_explorer1.py (edit that, not this file).
""" + header_common(args, s['mu'], s['EI'], s['GJ'], m, s['bus_mass'], s['Ixx'], s['Izz'], s['spin'], s['wx'],
                    s['Is'], s['It']) + f"""name: {name}
description: Explorer I, rigid bus spinning about its minor axis, four whips as rigid rods on sprung and damped flap hinges (the rigid-hinge twin of explorer1)
gravity: [0, 0, 0]

""" + bodies(s, whip_body) + f"""
initial:
  u: {{bus.wz: {s['spin']:.17g}, bus.wx: {s['wx']:.17g}}}

outputs: [energy, momentum]
"""
    return name, text


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--diameter-mm", type=float, default=1.6)
    ap.add_argument("--zeta", type=float, default=0.02)
    ap.add_argument("--seed-deg", type=float, default=1.0)
    ap.add_argument("--elements", type=int, default=8)
    ap.add_argument("--out-dir", default=os.path.join(os.path.dirname(__file__), "..", "models"))
    ap.add_argument("--suffix", default="")
    args = ap.parse_args()
    for name, text in (flexible_model(args), hinged_model(args)):
        path = os.path.join(args.out_dir, name + ".yaml")
        with open(path, "w") as f:
            f.write(text)
        print(path)


if __name__ == "__main__":
    main()
