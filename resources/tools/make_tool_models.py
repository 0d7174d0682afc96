#!/usr/bin/env python3
"""Generates the drawn models of LiverSim's three 5 mm laparoscopic instruments.

Writes probe.obj, forceps-body.obj, forceps-jaw.obj, scalpel.obj and the material library they
share, tools.mtl, into this script's own folder. Standard library only; every run writes the same
bytes.

Units: millimetres (the simulator scales the files by 1e-3 when it reads them).

Frame: the tool's own, the one its physics capsules use (core/interaction/include/liversim/interaction/tools.h).
Right-handed; the working end (probe ball centre, jaw hinge, blade heel) is at the origin; the
shaft runs along +z toward the surgeon's hand; the jaws and the blade reach along -z; the forceps
jaws open in the x-z plane, each turning about the y axis through the origin.

Sizes taken from the physics (capsule = a segment swept by a sphere): shaft radius 2.5 from z = 0
to z = 60; probe ball radius 3.0 centred at the origin; jaw 20 long, radius 1.5; blade from the
origin to (0, 0, -20), half-thickness 0.5. The collar and handle past z = 60 never touch tissue
and are there only so the instrument reads as one on screen.

Every part is a closed surface wound counter-clockwise seen from outside. Positions are shared
by a part's triangles; normals are given per triangle corner, smooth on curved surfaces and flat
on flat faces, so a crease carries two normals at one position.
"""

import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))

AROUND = 32          # segments around the shaft, collar and handle
BALL_RINGS = 16      # latitude steps of the probe ball, pole to pole
SHAFT_R = 2.5
SHAFT_END = 60.0     # the shaft is the physics capsule only up to here
MATERIAL_ORDER = ("steel", "grip", "handle")


# --- small vector helpers -------------------------------------------------------------------

def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def unit(v):
    length = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return (v[0] / length, v[1] / length, v[2] / length)


def num(x):
    # Fixed six decimals keep the output byte-stable; trailing zeros and "-0" only add noise.
    text = ("%.6f" % x).rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


# --- parts ----------------------------------------------------------------------------------

class Part:
    """One closed surface. Each triangle says how its corners are shaded:
    None          flat (the triangle's own normal),
    a string      a smoothing group (area-weighted mean of that group's triangles at the vertex),
    a callable    an exact normal from the position (spheres, cylinders, cones),
    a 3-tuple     the three corner normals themselves."""

    def __init__(self):
        self.pos = []
        self.tris = []

    def vertex(self, p):
        self.pos.append(tuple(float(c) for c in p))
        return len(self.pos) - 1

    def tri(self, i, j, k, material, shading=None):
        self.tris.append((i, j, k, material, shading))

    def resolved(self):
        """[(i, j, k, material, (n_i, n_j, n_k))] with every normal of unit length."""
        def area_vector(i, j, k):
            return cross(sub(self.pos[j], self.pos[i]), sub(self.pos[k], self.pos[i]))

        group_sum = {}
        for i, j, k, _, shading in self.tris:
            if isinstance(shading, str):
                a = area_vector(i, j, k)
                for v in (i, j, k):
                    s = group_sum.get((v, shading), (0.0, 0.0, 0.0))
                    group_sum[(v, shading)] = (s[0] + a[0], s[1] + a[1], s[2] + a[2])
        out = []
        for i, j, k, material, shading in self.tris:
            if shading is None:
                n = unit(area_vector(i, j, k))
                normals = (n, n, n)
            elif isinstance(shading, str):
                normals = tuple(unit(group_sum[(v, shading)]) for v in (i, j, k))
            elif callable(shading):
                normals = tuple(unit(shading(self.pos[v])) for v in (i, j, k))
            else:
                normals = tuple(unit(n) for n in shading)
            out.append((i, j, k, material, normals))
        return out

    def rotated(self, matrix):
        """A copy turned by a proper rotation (rows of `matrix`), its normals fixed first."""
        def turn(v):
            return tuple(sum(matrix[r][c] * v[c] for c in range(3)) for r in range(3))
        part = Part()
        part.pos = [turn(p) for p in self.pos]
        part.tris = [(i, j, k, m, tuple(turn(n) for n in ns)) for i, j, k, m, ns in self.resolved()]
        return part


def lathe(profile, around=AROUND):
    """A surface of revolution about z. `profile` runs from a point on the axis (bottom) to a
    point on the axis (top) as (r, z, smooth, material): `smooth` says the profile has no corner
    there, `material` colours the band from the previous point to this one. Points off the axis
    must have r > 0. Normals are exact around z; along the profile a smooth point takes the mean
    of its two bands' normals, which is exact for arcs sampled evenly."""
    part = Part()
    count = len(profile)
    band_normal = []
    for k in range(count - 1):
        dr = profile[k + 1][0] - profile[k][0]
        dz = profile[k + 1][1] - profile[k][1]
        length = math.hypot(dr, dz)
        band_normal.append((dz / length, -dr / length))  # (r, z); outward for bottom-to-top

    def end_normal(k, band):
        if not profile[k][2]:
            return band_normal[band]
        if k == 0:
            return (0.0, -1.0)
        if k == count - 1:
            return (0.0, 1.0)
        a, b = band_normal[k - 1], band_normal[k]
        length = math.hypot(a[0] + b[0], a[1] + b[1])
        return ((a[0] + b[0]) / length, (a[1] + b[1]) / length)

    angles = [2.0 * math.pi * j / around for j in range(around)]
    rings = []
    for r, z, _, _ in profile:
        if r == 0.0:
            rings.append([part.vertex((0.0, 0.0, z))] * around)  # a pole is one vertex
        else:
            rings.append([part.vertex((r * math.cos(t), r * math.sin(t), z)) for t in angles])

    def normal3(n2, j):
        return (n2[0] * math.cos(angles[j]), n2[0] * math.sin(angles[j]), n2[1])

    for k in range(count - 1):
        material = profile[k + 1][3]
        below, above = end_normal(k, k), end_normal(k + 1, k)
        for j in range(around):
            j1 = (j + 1) % around
            a, b, c, d = rings[k][j], rings[k][j1], rings[k + 1][j1], rings[k + 1][j]
            na, nb = normal3(below, j), normal3(below, j1)
            nc, nd = normal3(above, j1), normal3(above, j)
            if profile[k][0] > 0.0:      # a pole below leaves only the upper triangle
                part.tri(a, b, c, material, (na, nb, nc))
            if profile[k + 1][0] > 0.0:  # a pole above leaves only the lower triangle
                part.tri(a, c, d, material, (na, nc, nd))
    return part


def loft(sections, strips, bottom, top):
    """A closed surface through equal-length loops of points, `sections` in increasing z, each
    loop counter-clockwise seen from +z. strips[j] = (material, shading) for the band from loop
    point j to j+1. `bottom` and `top` are ("pole", point), closing the loops to that point, or
    ("cap", material), a flat fan from the loop's centroid."""
    part = Part()
    loops = [[part.vertex(p) for p in loop] for loop in sections]
    size = len(loops[0])
    for k in range(len(loops) - 1):
        for j in range(size):
            j1 = (j + 1) % size
            a, b, c, d = loops[k][j], loops[k][j1], loops[k + 1][j1], loops[k + 1][j]
            material, shading = strips[j]
            part.tri(a, b, c, material, shading)
            part.tri(a, c, d, material, shading)

    def close(loop, end, facing_up):
        kind, what = end
        if kind == "pole":
            centre, materials = part.vertex(what), strips
        else:
            points = [part.pos[v] for v in loop]
            centre = part.vertex(tuple(sum(p[i] for p in points) / len(points) for i in range(3)))
            materials = [(what, None)] * size
        for j in range(size):
            j1 = (j + 1) % size
            material, shading = materials[j]
            if facing_up:
                part.tri(centre, loop[j], loop[j1], material, shading)
            else:
                part.tri(centre, loop[j1], loop[j], material, shading)

    close(loops[0], bottom, False)
    close(loops[-1], top, True)
    return part


# --- the shared shaft, collar and handle ----------------------------------------------------

def handle_profile():
    """Collar and grip, z = 60 to 130, as lathe profile points after the shaft's last point."""
    p = []
    # Steel collar: a step out of the shaft, chamfered, as a real instrument's ferrule.
    p += [(3.0, 60.0, False, "steel"), (3.5, 60.5, False, "steel"), (3.5, 66.0, False, "steel")]
    # Plastic nose: a step onto the handle, then a taper easing into the grip.
    p += [(3.9, 66.0, False, "handle")]
    for i in range(1, 7):
        s = i / 6.0
        p.append((3.9 + 1.3 * math.sin(0.5 * math.pi * s), 66.0 + 7.0 * s, True, "handle"))

    def bead(centre_z, base_r, radius, steps=8):
        # A rounded ring standing out of the grip, corners where it meets it.
        out = []
        for i in range(steps + 1):
            a = -0.5 * math.pi + math.pi * i / steps
            out.append((base_r + radius * math.cos(a), centre_z + radius * math.sin(a),
                        0 < i < steps, "handle"))
        return out

    p += bead(75.0, 5.2, 0.8)                 # front finger ring, r 6.0
    # Grip: waisted a little, with shallow V grooves so it reads as a ribbed grip.
    z0, z1 = 75.8, 116.2
    grooves = (86.0, 92.0, 98.0, 104.0)

    def grip_r(z):
        return 5.2 - 0.3 * math.sin(math.pi * (z - z0) / (z1 - z0))

    zs = [z0 + (z1 - z0) * i / 16.0 for i in range(1, 16)]
    zs = [z for z in zs if all(abs(z - g) > 0.9 for g in grooves)]
    points = [(grip_r(z), z, True, "handle") for z in zs]
    for g in grooves:
        points += [(grip_r(g - 0.5), g - 0.5, False, "handle"),
                   (grip_r(g) - 0.3, g, False, "handle"),
                   (grip_r(g + 0.5), g + 0.5, False, "handle")]
    points.sort(key=lambda q: q[1])
    p += points
    p += [(5.2, z1, False, "handle")]
    p += bead(117.0, 5.2, 0.8)[1:]             # rear ring, r 6.0 (its first point is z1)
    # Palm end: a slight flare meeting a rounded butt at z = 130.
    for i in range(1, 5):
        s = i / 4.0
        p.append((5.2 + 0.4 * math.sin(0.5 * math.pi * s), 117.8 + 8.2 * s, True, "handle"))
    for i in range(1, 9):
        a = 0.5 * math.pi * i / 8
        r = 5.6 * math.cos(a)
        p.append((0.0 if i == 8 else r, 126.0 + 4.0 * math.sin(a), True, "handle"))
    return p


def tool_body(shaft_start=0.0, chamfer=0.0):
    """Shaft (r 2.5, from shaft_start to 60, flat or chamfered bottom), collar and handle."""
    p = [(0.0, shaft_start, False, "steel")]
    if chamfer > 0.0:
        p += [(SHAFT_R - chamfer, shaft_start, False, "steel"),
              (SHAFT_R, shaft_start + chamfer, False, "steel")]
    else:
        p += [(SHAFT_R, shaft_start, False, "steel")]
    p += [(SHAFT_R, SHAFT_END, False, "steel")]
    return lathe(p + handle_profile())


# --- the instruments ------------------------------------------------------------------------

def probe_parts():
    # Ball: evenly spaced latitudes so the lathe's averaged normals are exactly radial.
    ball = [(0.0, -3.0, True, "steel")]
    for i in range(1, BALL_RINGS + 1):
        a = -0.5 * math.pi + math.pi * i / BALL_RINGS
        r = 0.0 if i == BALL_RINGS else 3.0 * math.cos(a)
        ball.append((r, 3.0 * math.sin(a), True, "steel"))
    # The shaft starts at z = 0, its bottom hidden inside the ball.
    return [lathe(ball), tool_body(0.0)]


def forceps_body_parts():
    # The shaft stops at z = 2 so the jaws' hinge ends (which swing up to z = 0.5 when open)
    # clear it; the clevis cheeks straddle the jaws at |y| >= 1.6, inside the shaft's radius.
    parts = [tool_body(2.0, chamfer=0.3)]
    inner, outer, steps = 1.6, 2.45, 10
    a0 = math.asin(inner / outer)
    loop = [(outer * math.cos(a0 + (math.pi - 2 * a0) * i / steps),
             outer * math.sin(a0 + (math.pi - 2 * a0) * i / steps)) for i in range(steps + 1)]
    radial = (lambda p: (p[0], p[1], 0.0))
    strips = [("steel", radial)] * steps + [("steel", None)]  # curved outside, flat inner face
    for side in (1.0, -1.0):  # the -y cheek is the +y one turned half a turn about z
        sections = [[(side * x, side * y, z) for x, y in loop] for z in (0.0, 4.0)]
        parts.append(loft(sections, strips, ("cap", "steel"), ("cap", "steel")))
    # Hinge pin on the jaws' turning axis (y through the origin), through both cheeks.
    pin = lathe([(0.0, -2.3, False, "steel"), (0.4, -2.3, False, "steel"),
                 (0.5, -2.2, False, "steel"), (0.5, 2.2, False, "steel"),
                 (0.4, 2.3, False, "steel"), (0.0, 2.3, False, "steel")], around=24)
    parts.append(pin.rotated(((1, 0, 0), (0, 0, 1), (0, -1, 0))))  # lathe z -> y
    return parts


JAW_LENGTH = 20.0
JAW_ROOT_R = 1.5
JAW_TIP_R = 1.0                           # radius of the rounded tip
JAW_TIP_CENTRE = -JAW_LENGTH + JAW_TIP_R  # where the taper meets the tip's quarter sphere
JAW_TAPER = (JAW_ROOT_R - JAW_TIP_R) / -JAW_TIP_CENTRE  # dR/dz along the taper
JAW_ARC = 16                              # segments around the half-cylinder


def jaw_radius(z):
    return JAW_ROOT_R + JAW_TAPER * z


def jaw_normal(p):
    # Exact normals: the tapered half-cylinder (grad of r - R(z)) or the tip's sphere.
    x, y, z = p
    if z >= JAW_TIP_CENTRE - 1e-9:
        return (x, y, -JAW_TAPER * math.hypot(x, y))
    return (x, y, z - JAW_TIP_CENTRE)


def jaw_parts():
    # The gripping face is the plane x = 0; grooves cut into the jaw (toward +x) leave the tooth
    # tops on that plane, so the closed jaws meet there and nothing crosses to x < 0.
    depth, pitch, first, teeth = 0.3, 1.0, -1.0, 16
    stations = [(0.0, 0.0), (first, 0.0)]  # (z, depth of the face below x = 0)
    for t in range(teeth):
        z = first - pitch * t
        stations += [(z - 0.35, 0.0), (z - 0.5, depth), (z - 0.85, depth), (z - 1.0, 0.0)]
    stations += [(-18.0, 0.0), (JAW_TIP_CENTRE, 0.0)]
    sections = []
    for z, cut in stations:
        r = jaw_radius(z)
        half = math.acos(cut / r)  # the arc stops where it meets the (cut) face
        sections.append([(r * math.cos(-half + 2 * half * i / JAW_ARC),
                          r * math.sin(-half + 2 * half * i / JAW_ARC), z)
                         for i in range(JAW_ARC + 1)])
    for i in range(1, 6):  # the rounded tip, a quarter sphere, the face still flat at x = 0
        a = 0.5 * math.pi * i / 6
        r, z = JAW_TIP_R * math.cos(a), JAW_TIP_CENTRE - JAW_TIP_R * math.sin(a)
        sections.append([(r * math.cos(-0.5 * math.pi + math.pi * m / JAW_ARC),
                          r * math.sin(-0.5 * math.pi + math.pi * m / JAW_ARC), z)
                         for m in range(JAW_ARC + 1)])
    sections.reverse()  # loft wants increasing z
    # Loop: arc from -y round +x to +y (counter-clockwise from +z), then the face back to -y.
    strips = [("steel", jaw_normal)] * JAW_ARC + [("grip", None)]
    return [loft(sections, strips, ("pole", (0.0, 0.0, -JAW_LENGTH)), ("cap", "steel"))]


def scalpel_parts():
    # Lancet blade: half-width w = 1.5 t (2 - t) with t = 0 at the point and 1 at the heel, so
    # the sides are gently convex, parallel at the heel and meet at a sharp point; the spine
    # thins toward the point too so the point is a point, not a chisel. The outer 55 % of each
    # side is a bevel down to a knife edge at y = 0.
    length, steps = 20.0, 24
    sections = []
    for i in range(1, steps + 1):
        t = (i / steps) ** 1.3  # denser toward the point, where the shape changes fastest
        z = -length * (1.0 - t)
        w = 1.5 * t * (2.0 - t)
        h = 0.5 * (1.0 - (1.0 - t) ** 4)
        f = 0.45 * w
        sections.append([(w, 0.0, z), (f, h, z), (-f, h, z), (-w, 0.0, z), (-f, -h, z), (f, -h, z)])
    # Each face of the blade is its own smoothing group: smooth along the blade, creased across.
    strips = [("steel", "blade%d" % j) for j in range(6)]
    blade = loft(sections, strips, ("pole", (0.0, 0.0, -length)), ("cap", "steel"))
    return [blade, tool_body(0.0)]


# --- output ---------------------------------------------------------------------------------

def write_obj(filename, title, parts):
    positions, normals, normal_index = [], [], {}
    faces = {m: [] for m in MATERIAL_ORDER}
    for part in parts:
        base = len(positions)
        positions += part.pos
        for i, j, k, material, corner_normals in part.resolved():
            ids = []
            for n in corner_normals:
                key = " ".join(num(c) for c in n)
                if key not in normal_index:
                    normals.append(key)
                    normal_index[key] = len(normals)
                ids.append(normal_index[key])
            faces[material].append(((base + i + 1, ids[0]), (base + j + 1, ids[1]),
                                    (base + k + 1, ids[2])))
    lines = ["# LiverSim instrument model: " + title,
             "# Millimetres. Tool frame: working end at the origin, shaft along +z, tip along -z.",
             "# Generated by make_tool_models.py; edit that, not this.",
             "mtllib tools.mtl",
             "o " + os.path.splitext(filename)[0]]
    lines += ["v " + " ".join(num(c) for c in p) for p in positions]
    lines += ["vn " + n for n in normals]
    for material in MATERIAL_ORDER:
        if faces[material]:
            lines.append("usemtl " + material)
            lines += ["f " + " ".join("%d//%d" % corner for corner in face)
                      for face in faces[material]]
    with open(os.path.join(HERE, filename), "w", encoding="ascii", newline="\n") as out:
        out.write("\n".join(lines) + "\n")
    return sum(len(f) for f in faces.values())


MTL = """# LiverSim instrument materials, shared by the tools' OBJ files.
# Generated by make_tool_models.py; edit that, not this.

# Polished stainless steel: shaft, collar, ball, jaws, blade.
newmtl steel
Ka 0 0 0
Kd 0.72 0.74 0.78
Ks 0.9 0.9 0.9
Ns 60
d 1
illum 2

# The jaws' serrated gripping faces: slightly darker, duller steel.
newmtl grip
Ka 0 0 0
Kd 0.5 0.52 0.55
Ks 0.6 0.6 0.6
Ns 40
d 1
illum 2

# Dark blue-grey plastic handle.
newmtl handle
Ka 0 0 0
Kd 0.12 0.14 0.18
Ks 0.3 0.3 0.3
Ns 20
d 1
illum 2
"""


def main():
    with open(os.path.join(HERE, "tools.mtl"), "w", encoding="ascii", newline="\n") as out:
        out.write(MTL)
    for filename, title, parts in (
            ("probe.obj", "probe (ball r 3 at the origin, shaft, handle)", probe_parts()),
            ("forceps-body.obj", "forceps body (clevis, shaft, handle; no jaws)",
             forceps_body_parts()),
            ("forceps-jaw.obj", "forceps jaw 0, closed: hinge at the origin, on the +x side, "
             "gripping face x = 0", jaw_parts()),
            ("scalpel.obj", "scalpel (lancet blade from the origin to z = -20, shaft, handle)",
             scalpel_parts())):
        print("%-17s %5d triangles" % (filename, write_obj(filename, title, parts)))


if __name__ == "__main__":
    main()
