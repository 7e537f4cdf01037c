"""Builds the outside night streets in Blender (bpy) and exports them with Blender's own glTF
exporter: evaluation-only inputs for streak-robust stereo (tools/streak_eval/README.md).

    BLENDER_PYTHON tools/streak_eval/blender_streets.py OUT [--set b|...|i] [--scenes quay ...]

writes OUT/<scene>.glb (textures embedded) and OUT/<scene>.blend. The streets are not the
generator's (crates/scenes): a road that bends and climbs over a crest, a crossroads with a
crowned carriageway, their own textures (textures.py), lamps and cars. `--set b` builds the
second set instead (made after the first had been looked at): a roundabout at the foot of a
-4 % approach, a four-lane avenue with a tree-lined median, a bookcase (no road). `--set c`
builds the third (made after the first two had been looked at): a road descending through a
cutting under a railway bridge onto wet setts, lamps hung over the road and on walls; a narrow
banked street climbing a hill, seen from a truck; a dry street in sunshine (a sun, a sky as the
scene's `extras.streaks.environment`), whose road is flagged but shows no streaks. `--set d`
builds the fourth (made after the first three had been looked at): a road over a river bridge
with lamps on both parapets and the far bank's lit flats; a wide town square crossed by a tram
street, paved with large wet slabs, lamps on tall masts, seen from a low car. `--set e`
builds the fifth (made after the first four had been looked at): a harbour-side street of wet
cobbles beside a quay wall and the basin's dark water, lamps at varying heights (sodium posts,
LED lanterns and wall lamps), a parked van; a wide divided arterial road falling downhill into
a superelevated left bend, twin-arm lamp columns on its median barrier, a sign gantry and
oncoming headlights on the far carriageway, seen from an SUV. `--set f` builds the sixth (made
after the first five had been looked at): an old town's tram street, its double track set into
the wet asphalt under the overhead line, lit shop windows, a tram stop's shelter lit from
inside and an oncoming tram; a petrol station's forecourt of wet concrete with painted bays
under a canopy of bright LED panels, pumps, a shop, and a dark road beyond, seen from a van
through the 16-bit camera of sensor_f.toml. `--set g` builds the seventh (made after the first
six had been looked at): a motorway toll plaza, a wide wet expanse with booth islands, lane
signals and a sign gantry under high masts, cars queueing ahead and many headlights coming
through from the other side, seen through the 12-bit camera of sensor_g.toml; a narrow
residential close with cars parked along both kerbs, brick garden walls, porch lanterns and a
single street lamp, its wet asphalt full of large puddles. `--set h` builds the eighth (made
after the first seven had been looked at): a town-centre street past a bus station, its
bus bay under a long canopy of bright luminaires with lit adverts and buses standing in it,
and on the other kerb a shopping arcade's tall lit shop windows, a cinema's lit marquee and a
billboard, large lit surfaces near the camera whose mirror images lie wide on the wet road;
the open top deck of a multi-storey car park, wet stained concrete with painted bays, lamp
columns, parked cars, a stair tower and the town's blocks beyond the parapets, seen from a
van through the 12-bit camera of sensor_h.toml. `--set i` builds the ninth (made after the
first eight had been looked at): a boulevard past a grand hotel whose porte-cochere over its
drive has a glowing soffit, gold downlights and a lit fascia, opposite a car showroom's open
glass front into a brightly lit hall, large lit surfaces near the camera whose mirror images
lie wide on the wet road, seen from a low saloon; a mountain road climbing through a cutting
into a tunnel portal, the tunnel's lit interior (light lined walls, rows of luminaires)
bending away ahead, seen from a lorry through the 12-bit camera of sensor_i.toml.

The export is the exporter's defaults plus three Include choices a user ticks: cameras,
punctual lights and "Custom Properties" (`export_extras`): without the last one, the road
material's custom property `streaks = {"road": True}` and the objects' `streaks = {"class":
...}` are not written as glTF extras, and streaks cannot mask the road. After the export the
script reads the .glb back and fails unless the road's extras are there.

Blender is Z up; the exporter writes glTF's Y up (Blender (x, y, z) -> glTF (x, z, -y)).
Light levels follow docs/decisions/0030: luminaires of 1.5-3.5 kcd, headlights of about
14 kcd, tail lights of about 10 cd; a Blender spot or point lamp of P watts is exported as
P / (4 pi) * 683 cd times its colour, so P = 4 pi I_cd / (683 Y(colour)).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Callable
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "blender"))

import bpy  # type: ignore[import-not-found]  # noqa: E402
import numpy as np  # noqa: E402
import textures  # noqa: E402
from build import black_world, box_geometry, point_along, reset  # noqa: E402
from glb import read_glb  # noqa: E402
from levels import (  # noqa: E402
    crown,
    eased_grade,
    hill_profile,
    luminance,
    radiance_for_luminance,
    ramp_grade,
    smoothstep,
    watts_for_candela,
    watts_for_lux,
)

Vec3 = tuple[float, float, float]

#: Lamp colours (linear sRGB, peak 1): low-pressure sodium as docs/decisions/0030 gives it,
#: the others near their blackbody (high-pressure sodium 2050 K, LED 3000 K and 4000 K).
LPS = (1.0, 0.22, 0.0)
HPS = (1.0, 0.52, 0.17)
LED_3000 = (1.0, 0.71, 0.42)
LED_4000 = (1.0, 0.84, 0.66)
HALOGEN = (1.0, 0.78, 0.52)
RED = (1.0, 0.02, 0.01)
#: Second set: LED 5000 K (roundabout), metal halide 4200 K (avenue's median), xenon-like
#: cool headlights and a cool white shop / advert light box.
LED_5000 = (1.0, 0.93, 0.84)
METAL_HALIDE = (1.0, 0.88, 0.74)
XENON = (0.9, 0.95, 1.0)
COOL_WHITE = (0.92, 0.96, 1.0)


# --- materials --------------------------------------------------------------------------------


class Materials:
    """The scene's materials, made once each; textures loaded from `tex_folder`."""

    def __init__(self, tex_folder: Path):
        self.paths = textures.write_all(tex_folder)
        self.images: dict[str, bpy.types.Image] = {}
        self.cache: dict[str, bpy.types.Material] = {}

    def image(self, name: str) -> bpy.types.Image:
        if name not in self.images:
            img = bpy.data.images.load(str(self.paths[name]), check_existing=False)
            if not textures.TEXTURES[name][1]:
                img.colorspace_settings.name = "Non-Color"
            self.images[name] = img
        return self.images[name]

    def principled(
        self,
        name: str,
        colour: tuple[float, float, float] = (0.5, 0.5, 0.5),
        roughness: float = 0.8,
        metallic: float = 0.0,
        albedo: str | None = None,
        roughness_map: str | None = None,
        coat: float = 0.0,
        emission: tuple[float, float, float] | None = None,
        strength: float = 0.0,
        road: bool = False,
    ) -> bpy.types.Material:
        """A Principled BSDF material (cached by name). `albedo`: a colour texture for Base
        Color; `roughness_map`: a metallicRoughness image wired as Blender's glTF importer
        wires one (G roughness, B metallic); `road`: the custom property that the export
        writes as `extras.streaks.road = true`."""
        if name in self.cache:
            return self.cache[name]
        mat = bpy.data.materials.new(name)
        if not mat.node_tree:
            mat.use_nodes = True
        nodes, links = mat.node_tree.nodes, mat.node_tree.links
        bsdf = nodes["Principled BSDF"]
        bsdf.inputs["Base Color"].default_value = (*colour, 1.0)
        bsdf.inputs["Roughness"].default_value = roughness
        bsdf.inputs["Metallic"].default_value = metallic
        bsdf.inputs["Coat Weight"].default_value = coat
        if albedo is not None:
            node = nodes.new("ShaderNodeTexImage")
            node.image = self.image(albedo)
            node.location = (-500, 300)
            links.new(node.outputs["Color"], bsdf.inputs["Base Color"])
        if roughness_map is not None:
            node = nodes.new("ShaderNodeTexImage")
            node.image = self.image(roughness_map)
            node.location = (-700, 0)
            sep = nodes.new("ShaderNodeSeparateColor")
            sep.location = (-300, 0)
            links.new(node.outputs["Color"], sep.inputs["Color"])
            links.new(sep.outputs["Green"], bsdf.inputs["Roughness"])
            links.new(sep.outputs["Blue"], bsdf.inputs["Metallic"])
        if emission is not None:
            bsdf.inputs["Emission Color"].default_value = (*emission, 1.0)
            bsdf.inputs["Emission Strength"].default_value = strength
            bsdf.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        if road:
            mat["streaks"] = {"road": True}
        self.cache[name] = mat
        return mat


# --- geometry ---------------------------------------------------------------------------------


def tag(obj: bpy.types.Object, cls: str, instance: int | None = None) -> None:
    """The node's semantic class (and instance) as the custom property `streaks`."""
    props: dict[str, object] = {"class": cls}
    if instance is not None:
        props["instance"] = instance
    obj["streaks"] = props


def mesh_object(name, verts, faces, uvs, mat) -> bpy.types.Object:
    """A mesh object from vertices, faces and per-loop UVs (one (u, v) per face corner)."""
    me = bpy.data.meshes.new(name)
    me.from_pydata([tuple(map(float, v)) for v in verts], [], faces)
    layer = me.uv_layers.new(name="UVMap")
    k = 0
    for poly in me.polygons:
        for li in poly.loop_indices:
            layer.data[li].uv = uvs[k]
            k += 1
    me.update()
    obj = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(obj)
    obj.data.materials.append(mat)
    return obj


def box(name, lo: Vec3, hi: Vec3, mat, tile: float = 1.0, cls: str | None = None, inst=None):
    """An axis-aligned box (in its own frame) with UVs projected per face in metres / `tile`
    (vertical faces: along the face and up; horizontal faces: x and y)."""
    verts, faces = box_geometry(lo, hi)
    uvs = []
    for face in faces:
        pts = np.array([verts[i] for i in face])
        normal = np.cross(pts[1] - pts[0], pts[2] - pts[0])
        axis = int(np.argmax(np.abs(normal)))
        keep = {0: (1, 2), 1: (0, 2), 2: (0, 1)}[axis]
        uvs.extend((p[keep[0]] / tile, p[keep[1]] / tile) for p in pts)
    obj = mesh_object(name, verts, faces, uvs, mat)
    if cls is not None:
        tag(obj, cls, inst)
    return obj


def place(obj: bpy.types.Object, location: Vec3, heading: float) -> bpy.types.Object:
    """Puts `obj` at `location`, turned by `heading` radians about Z (0: its +Y along +Y)."""
    obj.location = location
    obj.rotation_euler = (0.0, 0.0, heading)
    return obj


def grid(name, xs, ys, height: Callable[[float, float], float], mat, tile: float):
    """A height-field mesh over the grid xs x ys (world X, Y), UVs x / tile, y / tile; faces
    wound to face up."""
    verts = [(x, y, height(x, y)) for y in ys for x in xs]
    nx = len(xs)
    faces, uvs = [], []
    for j in range(len(ys) - 1):
        for i in range(nx - 1):
            f = (j * nx + i, j * nx + i + 1, (j + 1) * nx + i + 1, (j + 1) * nx + i)
            faces.append(f)
            uvs.extend((verts[k][0] / tile, verts[k][1] / tile) for k in f)
    return mesh_object(name, verts, faces, uvs, mat)


class CentreLine:
    """A road's centre line: straight, then a left-hand arc of radius `radius` from
    `bend_start`; heights by `profile(s)`. `s` is the distance along it, from the camera."""

    def __init__(self, radius: float, bend_start: float, profile: Callable[[float], float]):
        self.radius, self.bend_start, self.profile = radius, bend_start, profile

    def heading(self, s: float) -> float:
        """Radians, anticlockwise from +Y (a left-hand bend turns towards -X)."""
        return max(0.0, s - self.bend_start) / self.radius

    def point(self, s: float) -> np.ndarray:
        if s <= self.bend_start:
            x, y = 0.0, s
        else:
            a = self.heading(s)
            x = -self.radius * (1.0 - math.cos(a))
            y = self.bend_start + self.radius * math.sin(a)
        return np.array([x, y, self.profile(s)])

    def right(self, s: float) -> np.ndarray:
        a = self.heading(s)
        return np.array([math.cos(a), math.sin(a), 0.0])

    def along(self, s: float) -> np.ndarray:
        a = self.heading(s)
        return np.array([-math.sin(a), math.cos(a), 0.0])


def ribbon(
    name,
    line: CentreLine,
    ss,
    profile,
    mat,
    tile: float,
    along_first: bool = False,
    bank: Callable[[float], float] | None = None,
):
    """A surface swept along `line`: at each s of `ss` the cross-section `profile`, a list of
    (x to the right, height above the centre line) from left to right, so that the faces
    face up (or towards the road, for a kerb or a facade). UVs in metres / `tile`: (across,
    along), or (along, across) when `along_first` (facades: along, then up). With `bank` the
    road is banked: at each s the cross-section is lifted by `bank(s) * x` (superelevation,
    a rise of bank(s) per metre to the right)."""
    across = [0.0]
    for (x0, h0), (x1, h1) in zip(profile, profile[1:], strict=False):
        across.append(across[-1] + math.hypot(x1 - x0, h1 - h0))
    verts, uv_of = [], []
    for s in ss:
        c, r = line.point(s), line.right(s)
        for (x, h), a in zip(profile, across, strict=True):
            lift = h if bank is None else h + bank(s) * x
            verts.append(c + x * r + np.array([0.0, 0.0, lift]))
            uv_of.append((s / tile, a / tile) if along_first else (a / tile, s / tile))
    m = len(profile)
    faces, uvs = [], []
    for j in range(len(ss) - 1):
        for i in range(m - 1):
            f = (j * m + i, j * m + i + 1, (j + 1) * m + i + 1, (j + 1) * m + i)
            faces.append(f)
            uvs.extend(uv_of[k] for k in f)
    return mesh_object(name, verts, faces, uvs, mat)


# --- lamps, cars, camera ----------------------------------------------------------------------


def spot(name, location: Vec3, direction: Vec3, watts, colour, size_deg, blend) -> None:
    """A punctual spot lamp (zero radius, no soft falloff)."""
    lamp = bpy.data.lights.new(name, "SPOT")
    lamp.color = colour
    lamp.energy = watts
    lamp.shadow_soft_size = 0.0
    lamp.use_soft_falloff = False
    lamp.spot_size = math.radians(size_deg)
    lamp.spot_blend = blend
    obj = bpy.data.objects.new(name, lamp)
    obj.location = location
    point_along(obj, direction)
    bpy.context.scene.collection.objects.link(obj)


def street_lamp(mats: Materials, name, foot: Vec3, heading: float, side: float, colour, cd):
    """A street lamp standing at `foot` on the pavement: a 7.5 m post, an arm reaching 1.6 m
    over the road (towards the side `-side`: side = +1 on the right of the street), a dark
    housing with an emissive lens under it (luminance I / A, as the generator's luminaires)
    and a spot light straight down, full to 60 degrees from the nadir, none past 85."""
    metal = mats.principled("lamp_metal", (0.08, 0.08, 0.09), roughness=0.5, metallic=0.6)
    post = box(f"{name}_post", (-0.07, -0.07, 0.0), (0.07, 0.07, 7.6), metal, cls="pole")
    place(post, foot, heading)
    reach = -side * 1.6
    lo, hi = min(0.0, reach), max(0.0, reach)
    arm = box(f"{name}_arm", (lo, -0.05, 7.45), (hi, 0.05, 7.55), metal, cls="pole")
    place(arm, foot, heading)
    head = box(f"{name}_head", (reach - 0.3, -0.18, 7.35), (reach + 0.3, 0.18, 7.5), metal)
    tag(head, "light_source")
    place(head, foot, heading)
    lens_area = 0.5 * 0.28
    lens = mats.principled(
        f"lens_{name}",
        emission=colour,
        strength=radiance_for_luminance(cd / lens_area, colour),
    )
    # The lens: a quad facing down just under the housing.
    z = 7.345
    verts = [(reach - 0.25, -0.14, z), (reach - 0.25, 0.14, z), (reach + 0.25, 0.14, z)]
    verts.append((reach + 0.25, -0.14, z))
    q = mesh_object(f"{name}_lens", verts, [(0, 1, 2, 3)], [(0, 0), (0, 1), (1, 1), (1, 0)], lens)
    tag(q, "light_source")
    place(q, foot, heading)
    c, s_ = math.cos(heading), math.sin(heading)
    world = (foot[0] + c * reach, foot[1] + s_ * reach, foot[2] + 7.3)
    spot(
        f"{name}_light",
        world,
        (0.0, 0.0, -1.0),
        watts_for_candela(cd, colour),
        colour,
        170.0,
        1.0 - 60.0 / 85.0,
    )


def car(mats: Materials, name, centre: Vec3, heading: float, paint, instance: int):
    """A car as two boxes (body and cabin) and four dark wheels' worth of skirt, 4.4 x 1.8 m,
    its front along its local +Y; returns the world transform function of local points."""
    body = box(f"{name}_body", (-0.9, -2.2, 0.3), (0.9, 2.2, 0.95), paint, cls="car", inst=instance)
    place(body, centre, heading)
    glass = mats.principled("car_glass", (0.02, 0.02, 0.025), roughness=0.05, coat=1.0)
    cabin = box(
        f"{name}_cabin", (-0.8, -1.2, 0.95), (0.8, 0.9, 1.45), glass, cls="car", inst=instance
    )
    place(cabin, centre, heading)
    tyre = mats.principled("tyre", (0.02, 0.02, 0.02), roughness=0.9)
    skirt = box(
        f"{name}_wheels", (-0.85, -1.9, 0.0), (0.85, 1.9, 0.3), tyre, cls="car", inst=instance
    )
    place(skirt, centre, heading)

    def to_world(p: Vec3) -> Vec3:
        c, s = math.cos(heading), math.sin(heading)
        return (centre[0] + c * p[0] - s * p[1], centre[1] + s * p[0] + c * p[1], centre[2] + p[2])

    return to_world


def car_light(
    mats,
    name,
    to_world,
    heading,
    local: Vec3,
    facing: float,
    colour,
    lens_cd_m2,
    cd,
    cone_deg,
    instance,
    pitch_deg=0.0,
):
    """A lamp of a car: an emissive 0.18 x 0.12 m lens facing along local +Y (`facing` = +1,
    the front) or -Y (-1), and a spot light of `cd` candela on axis along the same way,
    pitched down by `pitch_deg`."""
    mat = mats.principled(
        f"lens_{name}", emission=colour, strength=radiance_for_luminance(lens_cd_m2, colour)
    )
    x, y, z = local
    y += 0.01 * facing
    if facing > 0:
        verts = [
            (x - 0.09, y, z - 0.06),
            (x + 0.09, y, z - 0.06),
            (x + 0.09, y, z + 0.06),
            (x - 0.09, y, z + 0.06),
        ]
    else:
        verts = [
            (x + 0.09, y, z - 0.06),
            (x - 0.09, y, z - 0.06),
            (x - 0.09, y, z + 0.06),
            (x + 0.09, y, z + 0.06),
        ]
    q = mesh_object(
        name, [to_world(v) for v in verts], [(0, 1, 2, 3)], [(0, 0), (1, 0), (1, 1), (0, 1)], mat
    )
    tag(q, "light_source", instance)
    c, s = math.cos(heading), math.sin(heading)
    d_local = (0.0, facing * math.cos(math.radians(pitch_deg)), -math.sin(math.radians(pitch_deg)))
    d = (c * d_local[0] - s * d_local[1], s * d_local[0] + c * d_local[1], d_local[2])
    spot(
        f"{name}_light",
        to_world((x, y + 0.05 * facing, z)),
        d,
        watts_for_candela(cd, colour),
        colour,
        2.0 * cone_deg,
        0.5,
    )


def camera(name: str, location: Vec3, direction: Vec3, yfov_deg: float, w: int, h: int) -> None:
    """The driver's camera (the stereo rig's centre), vertical field of view `yfov_deg`."""
    cam = bpy.data.cameras.new(name)
    cam.sensor_fit = "VERTICAL"
    cam.angle_y = math.radians(yfov_deg)
    cam.clip_start = 0.05
    obj = bpy.data.objects.new(name, cam)
    obj.location = location
    point_along(obj, direction)
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.scene.camera = obj
    bpy.context.scene.render.resolution_x = w
    bpy.context.scene.render.resolution_y = h


def pitched(direction: np.ndarray, down_deg: float) -> Vec3:
    """A horizontal `direction` tilted down by `down_deg`."""
    d = direction / np.linalg.norm(direction)
    t = math.radians(down_deg)
    return (d[0] * math.cos(t), d[1] * math.cos(t), -math.sin(t))


# --- the streets ------------------------------------------------------------------------------


def build_hill_bend(mats: Materials) -> None:
    """A two-lane road (7 m) bending left on a 50 m radius and climbing over a crest, with
    12 cm kerbs, 2.5 m pavements, a terrace of facades following the bend, six street lamps
    (LED 3000 K, 2.4 kcd) staggered along it and a parked car."""
    line = CentreLine(radius=50.0, bend_start=12.0, profile=hill_profile)
    ss = np.arange(-8.0, 110.0, 1.0)
    road = mats.principled("wet_asphalt", albedo="asphalt", roughness_map="puddles", road=True)
    ribbon("road", line, ss, [(x, 0.0) for x in np.linspace(-3.5, 3.5, 8)], road, 2.0)
    tag(bpy.data.objects["road"], "road")
    paint = mats.principled("road_paint", (0.55, 0.55, 0.52), roughness=0.2, road=True)
    for k, s0 in enumerate(np.arange(2.0, 105.0, 6.0)):
        dash = ribbon(
            f"centre_dash_{k}",
            line,
            np.linspace(s0, s0 + 3.0, 4),
            [(-0.06, 0.004), (0.06, 0.004)],
            paint,
            1.0,
        )
        tag(dash, "marking")
    paving = mats.principled("paving", albedo="paving", roughness=0.35)
    kerb_right = [(3.5, 0.0), (3.5, 0.12), (6.0, 0.12)]
    kerb_left = [(-6.0, 0.12), (-3.5, 0.12), (-3.5, 0.0)]
    tag(ribbon("pavement_right", line, ss, kerb_right, paving, 1.0), "sidewalk")
    tag(ribbon("pavement_left", line, ss, kerb_left, paving, 1.0), "sidewalk")
    facades = [
        mats.principled("panels", albedo="panels", roughness=0.4),
        mats.principled("plaster", albedo="plaster", roughness=0.9),
        mats.principled("blocks", albedo="blocks", roughness=0.8),
    ]
    rng = np.random.default_rng(11)
    for side, x in (("right", 6.0), ("left", -6.0)):
        s0, k = -8.0, 0
        while s0 < 108.0:
            length = float(rng.uniform(10.0, 18.0))
            height = float(rng.uniform(7.0, 14.0))
            seg = np.linspace(s0, min(s0 + length, 110.0), 8)
            prof = [(x, -1.0), (x, height)] if side == "right" else [(x, height), (x, -1.0)]
            tile = 6.0 if k % 3 == 1 else 3.0
            obj = ribbon(f"facade_{side}_{k}", line, seg, prof, facades[k % 3], tile, True)
            tag(obj, "building")
            s0, k = s0 + length, k + 1
    for k, s in enumerate((6.0, 22.0, 38.0, 54.0, 70.0, 86.0)):
        side = 1.0 if k % 2 == 0 else -1.0
        foot = line.point(s) + 4.6 * side * line.right(s) + np.array([0.0, 0.0, 0.12])
        street_lamp(mats, f"lamp{k}", tuple(foot), line.heading(s), side, LED_3000, 2400.0)
    paint_blue = mats.principled(
        "paint_blue", (0.05, 0.09, 0.3), roughness=0.3, metallic=0.4, coat=1.0
    )
    s = 30.0
    centre = line.point(s) + 2.4 * line.right(s)
    car(mats, "parked_car", tuple(centre), line.heading(s), paint_blue, 1)
    eye = line.point(0.0) + 1.75 * line.right(0.0) + np.array([0.0, 0.0, 1.3])
    camera("driver", tuple(eye), pitched(line.along(0.0), 1.5), 42.0, 640, 480)


def build_crossing(mats: Materials) -> None:
    """A straight street (8 m, crowned by 8 cm) crossed by another (9 m, crowned by 8 cm,
    its crown fading out where it meets the first) 35-44 m ahead; corner pavements and
    buildings, low-pressure sodium lamps along the street, LED 4000 K lamps along the cross
    street, an oncoming car with its headlights on and a car ahead showing its tail lights."""
    road = mats.principled("wet_asphalt", albedo="asphalt", roughness_map="puddles", road=True)
    ys = np.arange(-10.0, 91.0, 1.0)
    grid("road", np.linspace(-4.0, 4.0, 17), ys, lambda x, y: crown(x, 4.0, 0.08), road, 2.0)
    tag(bpy.data.objects["road"], "road")
    y0, y1, yc = 35.0, 44.0, 39.5

    def cross_height(x: float, y: float) -> float:
        return crown(y - yc, 4.5, 0.08) * min(1.0, max(0.0, (abs(x) - 4.0) / 3.0))

    cys = np.linspace(y0, y1, 10)
    for name, xs in (
        ("cross_left", np.arange(-70.0, -3.99, 1.0)),
        ("cross_right", np.arange(4.0, 70.01, 1.0)),
    ):
        tag(grid(name, xs, cys, cross_height, road, 2.0), "road")
    paint = mats.principled("road_paint", (0.6, 0.6, 0.57), roughness=0.25, road=True)
    for k, y in enumerate(np.arange(-6.0, 33.0, 5.0)):
        tag(box(f"dash_{k}", (-0.06, y, 0.081), (0.06, y + 2.5, 0.085), paint), "marking")
    for k, y in enumerate(np.arange(46.0, 88.0, 5.0)):
        tag(box(f"dash_far_{k}", (-0.06, y, 0.081), (0.06, y + 2.5, 0.085), paint), "marking")
    # the stop line of our lane
    tag(box("stop_line", (0.0, 33.2, 0.0), (4.0, 33.6, 0.085), paint), "marking")
    paving = mats.principled("paving", albedo="paving", roughness=0.35)
    pav = 3.0
    for sx in (-1.0, 1.0):
        for near in (True, False):
            ya, yb = (-10.0, y0 - pav) if near else (y1 + pav, 90.0)
            yc0, yc1 = (y0 - pav, y0) if near else (y1, y1 + pav)
            xa, xb = sorted((sx * 4.0, sx * (4.0 + pav)))
            xc, xd = sorted((sx * 4.0, sx * 70.0))
            q = f"{'l' if sx < 0 else 'r'}{'n' if near else 'f'}"
            tag(box(f"pavement_{q}_a", (xa, ya, -0.2), (xb, yb, 0.12), paving), "sidewalk")
            tag(box(f"pavement_{q}_b", (xc, yc0, -0.2), (xd, yc1, 0.12), paving), "sidewalk")
    facades = [
        mats.principled("plaster", albedo="plaster", roughness=0.9),
        mats.principled("blocks", albedo="blocks", roughness=0.8),
        mats.principled("panels", albedo="panels", roughness=0.4),
    ]
    rng = np.random.default_rng(12)
    k = 0
    for sx in (-1.0, 1.0):
        for near in (True, False):
            # along the street: lots of 12-20 m
            ya, yb = (-10.0, y0 - pav) if near else (y1 + pav, 90.0)
            y = ya
            while y < yb - 1.0:
                ln = min(float(rng.uniform(12.0, 20.0)), yb - y)
                xa, xb = sorted((sx * (4.0 + pav), sx * (4.0 + pav + 12.0)))
                h = float(rng.uniform(8.0, 16.0))
                tag(
                    box(f"building_{k}", (xa, y, -0.5), (xb, y + ln, h), facades[k % 3], 3.0),
                    "building",
                )
                y, k = y + ln, k + 1
            # along the cross street
            yc0, yc1 = (y0 - pav - 12.0, y0 - pav) if near else (y1 + pav, y1 + pav + 12.0)
            xa, xb = sorted((sx * (4.0 + pav + 12.0), sx * 60.0))
            h = float(rng.uniform(8.0, 16.0))
            tag(
                box(f"building_{k}", (xa, yc0, -0.5), (xb, yc1, h), facades[k % 3], 3.0), "building"
            )
            k += 1
    # Lamps: low-pressure sodium along the street (staggered), LED 4000 K on the cross street.
    for k, y in enumerate((6.0, 24.0, 50.0, 68.0, 86.0)):
        side = 1.0 if k % 2 == 0 else -1.0
        street_lamp(mats, f"sodium{k}", (side * 5.0, y, 0.12), 0.0, side, LPS, 1800.0)
    for k, x in enumerate((-24.0, -10.0, 12.0, 26.0)):
        side = 1.0 if k % 2 == 0 else -1.0  # +1: the cross street's near (south) side
        foot = (x, y0 - 1.0 if side > 0 else y1 + 1.0, 0.12)
        # heading pi/2 turns local +X to +Y: the arm reaches north from the south side
        street_lamp(
            mats,
            f"led{k}",
            foot,
            math.pi / 2.0 if side > 0 else -math.pi / 2.0,
            -1.0,
            LED_4000,
            3000.0,
        )
    # The oncoming car (left lane, facing -Y) with dipped headlights.
    white = mats.principled("paint_white", (0.7, 0.7, 0.68), roughness=0.3, coat=1.0)
    to_world = car(mats, "oncoming_car", (-2.0, 58.0, 0.07), math.pi, white, 1)
    for k, x in enumerate((-0.65, 0.65)):
        car_light(
            mats,
            f"headlight{k}",
            to_world,
            math.pi,
            (x, 2.2, 0.7),
            1.0,
            HALOGEN,
            20000.0,
            14000.0,
            20.0,
            1,
            pitch_deg=1.5,
        )
    # The car ahead (our lane, facing +Y) shows its tail lights.
    red = mats.principled("paint_red", (0.35, 0.02, 0.02), roughness=0.3, metallic=0.3, coat=1.0)
    to_world = car(mats, "car_ahead", (2.0, 20.0, 0.06), 0.0, red, 2)
    for k, x in enumerate((-0.7, 0.7)):
        car_light(
            mats, f"taillight{k}", to_world, 0.0, (x, -2.2, 0.8), -1.0, RED, 800.0, 10.0, 40.0, 2
        )
    eye = (2.0, 0.0, crown(2.0, 4.0, 0.08) + 1.3)
    camera("driver", eye, pitched(np.array([0.0, 1.0, 0.0]), 1.0), 40.0, 800, 450)


class Circle:
    """A ring road's centre line: a circle of `radius` about `centre` (x, y), travelled
    anticlockwise from the angle `start` (radians from +X); height by `profile(s)`. Its
    right is outwards, so a `ribbon` profile runs from the inside (x < 0) out."""

    def __init__(self, centre, radius: float, start: float, profile: Callable[[float], float]):
        self.centre, self.radius, self.start, self.profile = centre, radius, start, profile

    def angle(self, s: float) -> float:
        return self.start + s / self.radius

    def heading(self, s: float) -> float:
        return self.angle(s) - math.pi / 2.0

    def point(self, s: float) -> np.ndarray:
        a = self.angle(s)
        x, y = (
            self.centre[0] + self.radius * math.cos(a),
            self.centre[1] + self.radius * math.sin(a),
        )
        return np.array([x, y, self.profile(s)])

    def right(self, s: float) -> np.ndarray:
        a = self.angle(s)
        return np.array([math.cos(a), math.sin(a), 0.0])

    def along(self, s: float) -> np.ndarray:
        a = self.angle(s)
        return np.array([-math.sin(a), math.cos(a), 0.0])


def drape(height: Callable[[float, float], float]) -> None:
    """Lays the scene, built level, on the terrain `height(x, y)`: every mesh vertex and every
    lamp and camera is raised by the height under it (walls stay vertical, roads follow)."""
    bpy.context.view_layer.update()
    for obj in bpy.context.scene.collection.objects:
        if obj.type == "MESH":
            m = obj.matrix_world
            inv = m.inverted()
            for v in obj.data.vertices:
                w = m @ v.co
                w.z += height(w.x, w.y)
                v.co = inv @ w
            obj.data.update()
        else:
            obj.location.z += height(obj.location.x, obj.location.y)


def tree(
    mats: Materials,
    name: str,
    foot: Vec3,
    height: float,
    conifer: bool,
    inst: int,
    leaves: str = "lawn",
):
    """A tree: a trunk (an 8-sided prism) and a crown, a cone (`conifer`) or a sphere, its
    leaves the texture `leaves`."""
    bark = mats.principled("bark", (0.06, 0.045, 0.035), roughness=0.9)
    leaves = mats.principled(
        f"leaves_{leaves}" if leaves != "lawn" else "leaves", albedo=leaves, roughness=0.85
    )
    trunk_h = 0.45 * height if conifer else 0.55 * height
    bpy.ops.mesh.primitive_cylinder_add(
        vertices=8, radius=0.12, depth=trunk_h, location=(foot[0], foot[1], foot[2] + trunk_h / 2)
    )
    trunk = bpy.context.active_object
    trunk.name = f"{name}_trunk"
    trunk.data.materials.append(bark)
    tag(trunk, "vegetation", inst)
    crown_h = height - trunk_h
    if conifer:
        bpy.ops.mesh.primitive_cone_add(
            vertices=12,
            radius1=0.35 * height,
            depth=crown_h + 0.3,
            location=(foot[0], foot[1], foot[2] + trunk_h - 0.3 + (crown_h + 0.3) / 2),
        )
        top = bpy.context.active_object
        top.name = f"{name}_crown"
        top.data.materials.append(leaves)
    else:
        centre = (foot[0], foot[1], foot[2] + trunk_h + crown_h / 2)
        top = sphere(f"{name}_crown", centre, crown_h / 2 + 0.4, leaves)
    tag(top, "vegetation", inst)


def sphere(name, centre: Vec3, radius: float, mat, segments: int = 16, rings: int = 8):
    """A UV sphere (quads, triangles at the poles) with UVs (longitude, latitude) / tile 1,
    built vertex by vertex (`bpy.ops`' UV sphere exports in a varying order)."""
    verts, faces, uvs = [], [], []
    for j in range(rings + 1):
        lat = math.pi * (j / rings - 0.5)
        for i in range(segments + 1):
            lon = 2.0 * math.pi * i / segments
            verts.append(
                (
                    centre[0] + radius * math.cos(lat) * math.cos(lon),
                    centre[1] + radius * math.cos(lat) * math.sin(lon),
                    centre[2] + radius * math.sin(lat),
                )
            )
    row = segments + 1
    for j in range(rings):
        for i in range(segments):
            a, b = j * row + i, j * row + i + 1
            c, d = (j + 1) * row + i + 1, (j + 1) * row + i
            quad = [(a, i, j), (b, i + 1, j), (c, i + 1, j + 1), (d, i, j + 1)]
            if j == 0:
                quad.pop(0)  # the south pole: one vertex
            elif j == rings - 1:
                quad.pop(2)  # the north pole
            faces.append(tuple(k for k, _, _ in quad))
            uvs.extend((u / segments, v / rings) for _, u, v in quad)
    return mesh_object(name, verts, faces, uvs, mat)


def headlights(mats, name, to_world, heading, inst, colour=XENON, cd=16000.0, pitch=1.2):
    """A car's two dipped headlights (`cd` on axis, 20 degree cones, pitched down)."""
    for k, x in enumerate((-0.65, 0.65)):
        car_light(
            mats,
            f"{name}{k}",
            to_world,
            heading,
            (x, 2.2, 0.7),
            1.0,
            colour,
            25000.0,
            cd,
            20.0,
            inst,
            pitch_deg=pitch,
        )


def tail_lights(mats, name, to_world, heading, inst, cd=10.0):
    """A car's two tail lights (`cd` candela, lens 800 cd/m2)."""
    for k, x in enumerate((-0.7, 0.7)):
        car_light(
            mats, f"{name}{k}", to_world, heading, (x, -2.2, 0.8), -1.0, RED, 800.0, cd, 40.0, inst
        )


def light_box(mats, name, lo: Vec3, hi: Vec3, heading: float, foot: Vec3, cd_m2: float, cls):
    """An emissive box (a shop window or an advert panel) of luminance `cd_m2`, cool white."""
    mat = mats.principled(
        f"glow_{name}", emission=COOL_WHITE, strength=radiance_for_luminance(cd_m2, COOL_WHITE)
    )
    return place(box(name, lo, hi, mat, cls=cls), foot, heading)


def point_lamp(name: str, location: Vec3, cd: float, colour) -> None:
    """A punctual point lamp of `cd` candela."""
    lamp = bpy.data.lights.new(name, "POINT")
    lamp.color = colour
    lamp.energy = watts_for_candela(cd, colour)
    lamp.shadow_soft_size = 0.0
    lamp.use_soft_falloff = False
    obj = bpy.data.objects.new(name, lamp)
    obj.location = location
    bpy.context.scene.collection.objects.link(obj)


def build_roundabout(mats: Materials) -> None:
    """A two-lane approach road (7 m) descending at -4 % into a roundabout 25-55 m ahead
    (a ring carriageway 8 m wide about a 7 m raised central island with a lawn, a plinth and
    two conifers), side roads leaving east and west, 15 cm kerbs, 3 m pavements, brick and
    rendered buildings set back 8-10 m, five LED 5000 K lamps of 2.8 kcd, a lit bus shelter
    with an advert light box, a shop window, a car ahead on the ring with its tail lights and
    a car on the ring with xenon headlights; the camera 1.5 m up (a van driver)."""
    yc, r_ring = 40.0, 11.0  # the island: 7 m
    r_out = r_ring + 4.0  # 15 m
    road = mats.principled("wet_asphalt", albedo="asphalt_b", roughness_map="puddles_b", road=True)
    paving = mats.principled("paving_b", albedo="paving_b", roughness=0.4)
    # the approach (x -3.5..3.5) and the side roads (y yc-3.5..yc+3.5), level meshes that
    # stop 0.6 m inside the ring's outer edge (they lie 5 mm under the ring there)
    approach_end = yc - r_out + 0.6
    grid(
        "road",
        np.linspace(-3.5, 3.5, 8),
        np.arange(-12.0, approach_end + 0.01, 1.0),
        lambda x, y: -0.005 if y > yc - r_out - 0.6 else 0.0,
        road,
        2.0,
    )
    tag(bpy.data.objects["road"], "road")
    for name, xs in (
        ("road_east", np.arange(r_out - 0.6, 80.01, 1.0)),
        ("road_west", np.arange(-80.0, -(r_out - 0.6) + 0.01, 1.0)),
    ):
        g = grid(
            name,
            xs,
            np.linspace(yc - 3.5, yc + 3.5, 8),
            lambda x, y: -0.005 if abs(x) < r_out + 0.6 else 0.0,
            road,
            2.0,
        )
        tag(g, "road")
    ring = Circle((0.0, yc), r_ring, 0.0, lambda s: 0.0)
    circ = 2.0 * math.pi * r_ring
    ss = np.linspace(0.0, circ, 97)
    tag(ribbon("ring", ring, ss, [(x, 0.0) for x in np.linspace(-4.0, 4.0, 5)], road, 2.0), "road")
    # the central island: a 15 cm kerb and a lawn, a plinth and two conifers on it
    kerb = mats.principled("kerb_stone", (0.3, 0.3, 0.29), roughness=0.6)
    tag(ribbon("island_kerb", ring, ss, [(-4.0, 0.15), (-4.0, 0.0)], kerb, 1.0), "sidewalk")
    grass = mats.principled("lawn", albedo="lawn", roughness=0.9)
    tag(ribbon("island", ring, ss, [(-10.9, 0.15), (-4.0, 0.15)], grass, 2.0), "terrain")
    plinth = mats.principled("plinth", albedo="render_b", roughness=0.8)
    tag(box("plinth", (-1.2, yc - 1.2, 0.0), (1.2, yc + 1.2, 2.2), plinth, 2.0), "building")
    tree(mats, "island_tree0", (-3.5, yc + 2.0, 0.15), 7.0, True, 1)
    tree(mats, "island_tree1", (3.8, yc + 1.0, 0.15), 5.5, True, 2)
    # the ring's outer kerb and pavement, open where the three roads meet it
    gaps = []
    for a in (-math.pi / 2.0, 0.0, math.pi):
        half = math.asin(3.5 / r_out) + 0.02
        gaps.append(((a - half) % (2 * math.pi), (a + half) % (2 * math.pi)))

    def open_at(s: float) -> bool:
        a = ring.angle(s) % (2 * math.pi)
        return any((lo <= a <= hi) if lo < hi else (a >= lo or a <= hi) for lo, hi in gaps)

    runs, cur = [], []
    for s in np.linspace(0.0, circ, 193):
        if open_at(s):
            if len(cur) > 1:
                runs.append(cur)
            cur = []
        else:
            cur.append(s)
    if len(cur) > 1:
        runs.append(cur)
    for k, run in enumerate(runs):
        prof = [(4.0, 0.0), (4.0, 0.15), (7.0, 0.15)]
        tag(ribbon(f"ring_pavement_{k}", ring, run, prof, paving, 1.0), "sidewalk")
    # pavements along the approach and the side roads, up to the ring's pavement
    y_ring = yc - math.sqrt(r_out**2 - 3.5**2)
    for sx in (-1.0, 1.0):
        xa, xb = sorted((sx * 3.5, sx * 6.5))
        tag(
            box(
                f"pavement_approach_{sx:+.0f}", (xa, -12.0, -0.2), (xb, y_ring - 0.2, 0.15), paving
            ),
            "sidewalk",
        )
        x_ring = math.sqrt(r_out**2 - 3.5**2)
        for sy in (-1.0, 1.0):
            ya, yb = sorted((yc + sy * 3.5, yc + sy * 6.5))
            xa, xb = sorted((sx * (x_ring + 0.2), sx * 80.0))
            tag(
                box(f"pavement_side_{sx:+.0f}{sy:+.0f}", (xa, ya, -0.2), (xb, yb, 0.15), paving),
                "sidewalk",
            )
    # the terrain between: dark ground, a little above the road, under the buildings
    ground = mats.principled("verge", albedo="lawn", roughness=0.9)
    for sx in (-1.0, 1.0):
        xa, xb = sorted((sx * 6.5, sx * 80.0))
        tag(
            box(f"verge_near_{sx:+.0f}", (xa, -12.0, -0.2), (xb, yc - 6.5, 0.1), ground, 2.0),
            "terrain",
        )
    tag(box("verge_far", (-80.0, yc + 6.5, -0.2), (80.0, 120.0, 0.1), ground, 2.0), "terrain")
    # buildings set back from the roads
    facades = [
        mats.principled("bricks", albedo="bricks", roughness=0.85),
        mats.principled("render_b", albedo="render_b", roughness=0.9),
    ]
    rng = np.random.default_rng(21)
    k = 0
    for sx in (-1.0, 1.0):
        y = -10.0
        while y < yc - 16.0:
            ln = float(rng.uniform(9.0, 14.0))
            x0 = sx * float(rng.uniform(14.0, 16.0))
            xa, xb = sorted((x0, x0 + sx * 10.0))
            h = float(rng.uniform(6.0, 11.0))
            tag(
                box(f"building_{k}", (xa, y, -0.5), (xb, y + ln, h), facades[k % 2], 3.0),
                "building",
            )
            y, k = y + ln + float(rng.uniform(2.0, 5.0)), k + 1
    for x0 in (-60.0, -38.0, 22.0, 44.0):
        h = float(rng.uniform(8.0, 14.0))
        tag(
            box(
                f"building_{k}",
                (x0, yc + 14.0, -0.5),
                (x0 + 18.0, yc + 26.0, h),
                facades[k % 2],
                3.0,
            ),
            "building",
        )
        k += 1
    # a shop window on the nearest right-hand building's front (facing the road, -X)
    light_box(
        mats,
        "shop_window",
        (-0.05, -4.0, 0.3),
        (0.0, 4.0, 2.6),
        0.0,
        (14.0 - 0.01, 6.0, 0.0),
        120.0,
        "building",
    )
    # the bus shelter on the left pavement, its advert light box facing the road
    glassy = mats.principled("shelter_frame", (0.1, 0.1, 0.11), roughness=0.4, metallic=0.7)
    foot = (-5.6, 18.0, 0.15)
    tag(
        place(box("shelter_roof", (-0.8, -2.0, 2.3), (0.8, 2.0, 2.4), glassy), foot, 0.0),
        "street_furniture",
    )
    tag(
        place(box("shelter_back", (-0.8, -2.0, 0.0), (-0.75, 2.0, 2.3), glassy), foot, 0.0),
        "street_furniture",
    )
    light_box(
        mats,
        "shelter_advert",
        (-0.6, 1.9, 0.3),
        (0.6, 2.0, 2.1),
        0.0,
        foot,
        350.0,
        "street_furniture",
    )
    point_lamp("shelter_light", (foot[0], foot[1], 2.2), 150.0, COOL_WHITE)
    # five LED 5000 K lamps: two along the approach, three round the ring, arms over the road
    for k, y in enumerate((4.0, 16.0)):
        side = 1.0 if k % 2 == 0 else -1.0
        street_lamp(mats, f"led{k}", (side * 4.6, y, 0.15), 0.0, side, LED_5000, 2800.0)
    for k, a in enumerate((-0.25 * math.pi, 0.5 * math.pi, 1.25 * math.pi)):
        foot = (1.2 + r_out) * np.array([math.cos(a), math.sin(a), 0.0]) + np.array([0, yc, 0.15])
        street_lamp(mats, f"ring_led{k}", tuple(foot), a, 1.0, LED_5000, 2800.0)
    # a car ahead on the ring (tail lights) and one coming round it (headlights)
    red = mats.principled("paint_maroon", (0.2, 0.03, 0.05), roughness=0.3, metallic=0.3, coat=1.0)
    s = (-0.5 * math.pi + 0.55) * r_ring  # just past the entry, going right
    c = ring.point(s) + 1.8 * ring.right(s)
    tw = car(mats, "car_ahead", tuple(c), ring.heading(s), red, 1)
    tail_lights(mats, "taillight", tw, ring.heading(s), 1)
    silver = mats.principled("paint_silver", (0.45, 0.46, 0.48), roughness=0.25, metallic=0.8)
    s = (0.75 * math.pi) * r_ring
    c = ring.point(s) - 1.6 * ring.right(s)
    tw = car(mats, "car_ring", tuple(c), ring.heading(s), silver, 2)
    headlights(mats, "headlight", tw, ring.heading(s), 2)
    drape(lambda x, y: eased_grade(y, -0.04, 14.0, 12.0))
    dz = -0.04
    eye = (1.75, 0.0, 1.5)
    d = np.array([0.0, 1.0, dz])
    camera("driver", eye, pitched(d, 2.0), 44.0, 640, 400)


def build_avenue(mats: Materials) -> None:
    """A straight four-lane avenue: two 7 m carriageways either side of a 3 m raised median
    with a lawn, broadleaf trees and twin-arm metal-halide lamps (4200 K, 3.2 kcd a head);
    4 m pavements with high-pressure sodium lamps (2 kcd) on both sides, bricks and rendered
    facades; a wet road with strong puddles (a third of it at roughness 0.02); oncoming cars
    with xenon headlights in the far lanes; the camera 1.15 m up in the inner lane."""
    road = mats.principled(
        "wet_asphalt", albedo="asphalt_b", roughness_map="puddles_strong", road=True
    )
    ys = np.arange(-10.0, 151.0, 2.0)
    for name, xa, xb in (("road_near", 1.5, 8.5), ("road_far", -8.5, -1.5)):
        tag(grid(name, np.linspace(xa, xb, 8), ys, lambda x, y: 0.0, road, 2.0), "road")
    paint = mats.principled("road_paint", (0.6, 0.6, 0.57), roughness=0.25, road=True)
    k = 0
    for x in (5.0, -5.0):
        for y in np.arange(-8.0, 148.0, 9.0):
            tag(
                box(f"lane_dash_{k}", (x - 0.06, y, 0.0), (x + 0.06, y + 3.0, 0.004), paint),
                "marking",
            )
            k += 1
    kerb = mats.principled("kerb_stone", (0.3, 0.3, 0.29), roughness=0.6)
    grass = mats.principled("lawn", albedo="lawn", roughness=0.9)
    tag(box("median_kerb", (-1.5, -10.0, -0.1), (1.5, 150.0, 0.12), kerb, 1.0), "sidewalk")
    tag(box("median_lawn", (-1.35, -10.0, 0.0), (1.35, 150.0, 0.14), grass, 2.0), "terrain")
    paving = mats.principled("paving_b", albedo="paving_b", roughness=0.4)
    facades = [
        mats.principled("render_b", albedo="render_b", roughness=0.9),
        mats.principled("bricks", albedo="bricks", roughness=0.85),
    ]
    rng = np.random.default_rng(22)
    k = 0
    for sx in (-1.0, 1.0):
        xa, xb = sorted((sx * 8.5, sx * 12.5))
        tag(box(f"pavement_{sx:+.0f}", (xa, -10.0, -0.2), (xb, 150.0, 0.13), paving), "sidewalk")
        y = -10.0
        while y < 148.0:
            ln = float(rng.uniform(14.0, 24.0))
            xa, xb = sorted((sx * 12.5, sx * 24.0))
            h = float(rng.uniform(12.0, 22.0))
            tag(
                box(f"building_{k}", (xa, y, -0.5), (xb, y + ln, h), facades[k % 2], 3.0),
                "building",
            )
            y, k = y + ln, k + 1
    # trees on the median, lamps between them
    for k, y in enumerate(np.arange(6.0, 140.0, 12.0)):
        tree(
            mats,
            f"median_tree{k}",
            (0.0, float(y), 0.14),
            float(rng.uniform(5.0, 7.0)),
            False,
            k + 1,
        )
    for k, y in enumerate(np.arange(12.0, 140.0, 24.0)):
        for j, side in enumerate((-1.0, 1.0)):
            # the arm of side -1 reaches +X (over our carriageway), of +1 over the far one
            street_lamp(
                mats, f"median{k}_{j}", (0.0, float(y), 0.14), 0.0, side, METAL_HALIDE, 3200.0
            )
    for k, y in enumerate(np.arange(0.0, 140.0, 20.0)):
        for sx in (-1.0, 1.0):
            yy = float(y) + (10.0 if sx < 0 else 0.0)
            street_lamp(mats, f"sodium{k}_{sx:+.0f}", (sx * 9.1, yy, 0.13), 0.0, sx, HPS, 2000.0)
    # oncoming cars in the far lanes, a car ahead in ours
    paints = [
        mats.principled("paint_black", (0.02, 0.02, 0.02), roughness=0.2, coat=1.0),
        mats.principled("paint_white", (0.7, 0.7, 0.68), roughness=0.3, coat=1.0),
        mats.principled("paint_green", (0.04, 0.15, 0.08), roughness=0.3, metallic=0.4, coat=1.0),
    ]
    for k, (x, y) in enumerate(((-3.25, 38.0), (-6.75, 62.0), (-3.25, 95.0))):
        tw = car(mats, f"oncoming{k}", (x, y, 0.0), math.pi, paints[k], k + 1)
        headlights(
            mats,
            f"headlight{k}_",
            tw,
            math.pi,
            k + 1,
            colour=XENON if k != 1 else HALOGEN,
            cd=15000.0,
        )
    tw = car(mats, "car_ahead", (6.75, 30.0, 0.0), 0.0, paints[1], 4)
    tail_lights(mats, "taillight", tw, 0.0, 4)
    camera("driver", (3.25, 0.0, 1.15), pitched(np.array([0.0, 1.0, 0.0]), 0.8), 38.0, 720, 405)


def build_shelf(mats: Materials) -> None:
    """A Middlebury-like close-range scene without streaks, other than the tabletop: a wooden
    bookcase before a wallpapered wall, books (spines) of several heights, standing and lying,
    a box file and two boxes, a pot; matte only (roughness 0.85-0.95), lit by three point
    lamps (500-900 cd); the camera 1.1-1.9 m from the objects. No road, no gloss."""
    wall = mats.principled("wallpaper", albedo="wallpaper", roughness=0.95)
    tag(box("wall", (-2.5, 0.4, -0.1), (2.5, 0.5, 2.6), wall, 0.8), "wall")
    floor = mats.principled("floorboards", albedo="wood", roughness=0.9)
    tag(box("floor", (-2.5, -2.5, -0.1), (2.5, 0.4, 0.0), floor, 1.2), "terrain")
    oak = mats.principled("shelf_wood", albedo="wood", roughness=0.85)
    # the bookcase: 1.2 m wide, 0.3 m deep, boards at 0.05, 0.45, 0.85, 1.25 m, 1.6 m tall
    x0, x1, yb, yf = -0.6, 0.6, 0.1, 0.4
    parts = [
        ("side_l", (x0 - 0.02, yb, 0.0), (x0, yf, 1.62)),
        ("side_r", (x1, yb, 0.0), (x1 + 0.02, yf, 1.62)),
        ("back", (x0, yf - 0.01, 0.0), (x1, yf, 1.62)),
    ]
    parts += [
        (f"board{k}", (x0, yb, z), (x1, yf, z + 0.02))
        for k, z in enumerate((0.03, 0.45, 0.85, 1.25, 1.6))
    ]
    for name, lo, hi in parts:
        tag(box(name, lo, hi, oak, 0.6), "street_furniture")
    spines = mats.principled("spines", albedo="spines", roughness=0.9)
    boxes = mats.principled("box_card", albedo="bricks", roughness=0.9)
    render = mats.principled("box_paper", albedo="render_b", roughness=0.9)
    rng = np.random.default_rng(23)
    inst = 1
    for k, z in enumerate((0.05, 0.47, 0.87, 1.27)):
        x = x0 + 0.02
        end = x1 - (0.35 if k % 2 == 0 else 0.05)
        while x < end - 0.03:
            w = float(rng.uniform(0.02, 0.05))
            h = float(rng.uniform(0.22, 0.34))
            d = float(rng.uniform(0.17, 0.25))
            # the spine faces the camera (-Y): tile 0.3 m maps the spines' strips across
            tag(
                box(f"book{inst}", (x, yb + 0.01, z), (x + w, yb + d, z + h), spines, 0.3),
                "street_furniture",
                inst,
            )
            x, inst = x + w + 0.002, inst + 1
        if k % 2 == 0:
            # a lying stack and a box in the remaining space
            for j in range(3):
                t = 0.04
                tag(
                    box(
                        f"stack{k}_{j}",
                        (end + 0.02 + 0.01 * j, yb + 0.03, z + j * t),
                        (x1 - 0.03 - 0.01 * j, yb + 0.26, z + (j + 1) * t),
                        spines,
                        0.25,
                    ),
                    "street_furniture",
                    inst,
                )
                inst += 1
            tag(
                box(
                    f"box{k}",
                    (end + 0.05, yb + 0.05, z + 0.12),
                    (x1 - 0.06, yb + 0.24, z + 0.3),
                    boxes,
                    0.4,
                ),
                "street_furniture",
                inst,
            )
            inst += 1
    # on the floor before the bookcase: a box and a pot (a cylinder)
    tag(
        box("floor_box", (-0.95, -0.5, 0.0), (-0.55, -0.15, 0.35), render, 0.5),
        "street_furniture",
        inst,
    )
    bpy.ops.mesh.primitive_cylinder_add(
        vertices=32, radius=0.15, depth=0.4, location=(0.8, -0.3, 0.2)
    )
    pot = bpy.context.active_object
    pot.name = "pot"
    pot.data.materials.append(mats.principled("pot_clay", albedo="bricks", roughness=0.9))
    tag(pot, "street_furniture", inst + 1)
    warm = (1.0, 0.9, 0.78)
    for k, (loc, cd) in enumerate(
        (((-1.3, -1.2, 2.1), 900.0), ((1.5, -1.4, 1.6), 600.0), ((0.2, -2.0, 0.4), 500.0))
    ):
        point_lamp(f"room_lamp{k}", loc, cd, warm)
    eye = np.array([0.1, -1.6, 1.05])
    target = np.array([0.0, 0.25, 0.8])
    camera("camera", tuple(eye), tuple(target - eye), 48.0, 640, 480)


def build_tabletop(mats: Materials) -> None:
    """A Middlebury-like close-range scene without streaks: matte, textured objects on a
    table before a textured backdrop, lit by two point lamps (800 cd each), an indoor
    scene; the camera 1.4-2.5 m from the objects. No road, no wet or glossy surface."""
    top = mats.principled("table_top", albedo="plaster", roughness=0.85)
    tag(box("table", (-0.9, -0.5, 0.0), (0.9, 0.6, 0.75), top, 0.5), "street_furniture")
    wall = mats.principled("backdrop", albedo="panels", roughness=0.9)
    tag(box("backdrop", (-2.5, 0.9, 0.0), (2.5, 1.0, 2.5), wall, 1.5), "wall")
    floor = mats.principled("floor", albedo="paving", roughness=0.9)
    tag(box("floor", (-2.5, -3.0, -0.05), (2.5, 1.0, 0.0), floor, 1.0), "terrain")
    blocks = mats.principled("blocks_matte", albedo="blocks", roughness=0.9)
    grain = mats.principled("grain_matte", albedo="asphalt", roughness=0.9)
    paving = mats.principled("paving_matte", albedo="paving", roughness=0.9)
    items = (
        ("crate", (-0.55, -0.1, 0.75), (-0.25, 0.25, 1.05), blocks, 0.3),
        ("tower", (0.3, 0.1, 0.75), (0.5, 0.3, 1.25), paving, 0.2),
        ("slab", (-0.1, -0.35, 0.75), (0.25, -0.1, 0.85), grain, 0.1),
        ("post", (0.6, -0.3, 0.75), (0.7, -0.2, 1.1), blocks, 0.15),
    )
    for k, (name, lo, hi, mat, tile) in enumerate(items):
        tag(box(name, lo, hi, mat, tile), "street_furniture", k + 1)
    bpy.ops.mesh.primitive_uv_sphere_add(
        segments=48, ring_count=24, radius=0.12, location=(0.05, 0.3, 0.87)
    )
    ball = bpy.context.active_object
    ball.name = "ball"
    bpy.ops.object.shade_smooth()
    ball.data.materials.append(mats.principled("ball_matte", albedo="plaster", roughness=0.9))
    tag(ball, "street_furniture", 9)
    white = (1.0, 0.95, 0.9)
    for k, loc in enumerate(((-1.2, -1.0, 2.2), (1.4, -0.6, 1.9))):
        lamp = bpy.data.lights.new(f"room_lamp{k}", "POINT")
        lamp.color = white
        lamp.energy = watts_for_candela(800.0, white)
        lamp.shadow_soft_size = 0.0
        lamp.use_soft_falloff = False
        obj = bpy.data.objects.new(f"room_lamp{k}", lamp)
        obj.location = loc
        bpy.context.scene.collection.objects.link(obj)
    eye = np.array([0.0, -1.5, 1.35])
    target = np.array([0.0, 0.3, 0.9])
    camera("camera", tuple(eye), tuple(target - eye), 40.0, 640, 480)


# --- the third set ----------------------------------------------------------------------------

#: Third set's lamp colours, blackbodies in linear sRGB (integrated against the CIE 1931
#: observer, peak 1): LED 2200 K and 2700 K (warm), LED 5700 K (cool), a noon sun (5700 K)
#: and a blue sky.
LED_2200 = (1.0, 0.31, 0.03)
LED_2700 = (1.0, 0.42, 0.10)
LED_5700 = (1.0, 0.87, 0.80)
SUN = (1.0, 0.87, 0.80)
SKY = (0.45, 0.62, 1.0)
SHOP_WARM = (1.0, 0.57, 0.26)


def lamp_head(mats, name, centre: Vec3, size: tuple[float, float], colour, cd) -> None:
    """A luminaire head centred at `centre`: a dark housing `size` (x, y) metres and 0.15 m
    tall, an emissive lens facing down under it (luminance I / A) and a spot light straight
    down, full to 60 degrees from the nadir and none past 85 (decision 0030's luminaire)."""
    metal = mats.principled("lamp_metal_c", (0.12, 0.12, 0.12), roughness=0.45, metallic=0.6)
    sx, sy = size
    x, y, z = centre
    head = box(
        f"{name}_head", (x - sx / 2, y - sy / 2, z), (x + sx / 2, y + sy / 2, z + 0.15), metal
    )
    tag(head, "light_source")
    lx, ly = 0.4 * sx, 0.4 * sy
    lens = mats.principled(
        f"lens_{name}",
        emission=colour,
        strength=radiance_for_luminance(cd / (4.0 * lx * ly), colour),
    )
    zl = z - 0.005
    verts = [(x - lx, y - ly, zl), (x - lx, y + ly, zl), (x + lx, y + ly, zl), (x + lx, y - ly, zl)]
    q = mesh_object(f"{name}_lens", verts, [(0, 1, 2, 3)], [(0, 0), (0, 1), (1, 1), (1, 0)], lens)
    tag(q, "light_source")
    spot(
        f"{name}_light",
        (x, y, z - 0.05),
        (0.0, 0.0, -1.0),
        watts_for_candela(cd, colour),
        colour,
        170.0,
        1.0 - 60.0 / 85.0,
    )


def wall_lamp(mats, name, wall: Vec3, out: float, colour, cd) -> None:
    """A wall-mounted luminaire: a bracket from the wall point `wall` (x, y, z) reaching 0.7 m
    along X (`out` = +1 or -1, towards the road) and a 0.45 x 0.3 m head at its end."""
    metal = mats.principled("lamp_metal_c", (0.12, 0.12, 0.12), roughness=0.45, metallic=0.6)
    x, y, z = wall
    xa, xb = sorted((x, x + out * 0.7))
    tag(box(f"{name}_bracket", (xa, y - 0.04, z + 0.1), (xb, y + 0.04, z + 0.16), metal), "pole")
    lamp_head(mats, name, (x + out * 0.75, y, z), (0.45, 0.3), colour, cd)


def catenary_lamp(mats, name, x_span: tuple[float, float], centre: Vec3, colour, cd) -> None:
    """A lamp hung over the road's centre from a span wire between x_span (the wire 0.4 m
    above the head, a drop rod to it): a round-ish 0.5 x 0.5 m head."""
    metal = mats.principled("lamp_metal_c", (0.12, 0.12, 0.12), roughness=0.45, metallic=0.6)
    x, y, z = centre
    zw = z + 0.55
    tag(
        box(f"{name}_wire", (x_span[0], y - 0.01, zw), (x_span[1], y + 0.01, zw + 0.02), metal),
        "pole",
    )
    tag(
        box(f"{name}_drop", (x - 0.02, y - 0.02, z + 0.15), (x + 0.02, y + 0.02, zw), metal), "pole"
    )
    lamp_head(mats, name, centre, (0.5, 0.5), colour, cd)


def wall(name, ys, x: float, z_lo, z_hi, mat, tile: float, facing: float):
    """A vertical wall along Y at `x` between heights z_lo(y) and z_hi(y), facing -X (`facing`
    = -1) or +X (+1); UVs (along, up) in metres / `tile`."""
    verts, faces, uvs = [], [], []
    for y in ys:
        verts += [(x, y, z_lo(y)), (x, y, z_hi(y))]
    for j in range(len(ys) - 1):
        a, b, c, d = 2 * j, 2 * j + 2, 2 * j + 3, 2 * j + 1
        f = (a, b, c, d) if facing > 0 else (a, d, c, b)
        faces.append(f)
        uvs.extend((verts[k][1] / tile, verts[k][2] / tile) for k in f)
    return mesh_object(name, verts, faces, uvs, mat)


def sloped_to_world(centre: Vec3, heading: float, pitch: float) -> Callable[[Vec3], Vec3]:
    """The local-to-world map of an object at `centre` turned by `heading` about Z and pitched
    nose-up (its local +Y rising) by `pitch` radians: Blender's rotation_euler (pitch, 0,
    heading)."""
    cp, sp = math.cos(pitch), math.sin(pitch)
    c, s = math.cos(heading), math.sin(heading)

    def to_world(p: Vec3) -> Vec3:
        x, y, z = p[0], cp * p[1] - sp * p[2], sp * p[1] + cp * p[2]
        return (centre[0] + c * x - s * y, centre[1] + s * x + c * y, centre[2] + z)

    return to_world


def sloped_car(mats, name, centre: Vec3, heading: float, pitch: float, paint, instance: int):
    """`car` pitched nose-up by `pitch` radians (on a grade); returns its local-to-world map."""
    car(mats, name, centre, heading, paint, instance)
    for part in ("body", "cabin", "wheels"):
        bpy.data.objects[f"{name}_{part}"].rotation_euler = (pitch, 0.0, heading)
    return sloped_to_world(centre, heading, pitch)


def straight(profile: Callable[[float], float]) -> CentreLine:
    """A straight centre line along +Y with heights `profile(y)`."""
    return CentreLine(radius=1e9, bend_start=1e9, profile=profile)


def build_underpass(mats: Materials) -> None:
    """A two-lane road (7 m) descending at -6 % in a cutting between board-marked concrete
    retaining walls (easing to level 22-38 m ahead, 1.8 m down) and passing under a railway
    bridge 44-56 m ahead (sandstone abutments and embankment, a concrete deck 4.6 m over the
    road); beyond it a level street of wet granite setts between shop fronts and rendered
    terraces. Lamps hung over the road's centre from span wires (LED 2700 K, 2.2 kcd), cool
    wall-mounted lamps in the underpass and on the facades (LED 5700 K, 1.2-1.5 kcd); a car
    ahead on the descent with its tail lights, an oncoming car in the underpass with LED
    headlights; wet asphalt (roughness 0.11, puddles 0.03 on a third) and wet setts (stones
    about 0.2, water in the joints 0.05); the camera 1.3 m up (a car)."""

    def h(y: float) -> float:
        return eased_grade(y, -0.06, 22.0, 16.0)

    line = straight(h)
    low = h(40.0)  # -1.8 m
    asphalt = mats.principled(
        "wet_asphalt", albedo="asphalt_c", roughness_map="puddles_c", road=True
    )
    setts_mat = mats.principled("wet_setts", albedo="setts", roughness_map="setts_wet", road=True)
    xs = [(x, 0.0) for x in np.linspace(-3.5, 3.5, 8)]
    tag(ribbon("road", line, np.arange(-10.0, 58.01, 1.0), xs, asphalt, 2.0), "road")
    tag(ribbon("road_setts", line, np.arange(58.0, 140.01, 2.0), xs, setts_mat, 1.5), "road")
    paint = mats.principled("road_paint_c", (0.62, 0.6, 0.5), roughness=0.22, road=True)
    for k, y0 in enumerate(np.arange(-6.0, 56.0, 4.5)):
        dash = ribbon(
            f"centre_dash_{k}",
            line,
            np.linspace(y0, y0 + 2.0, 3),
            [(-0.07, 0.004), (0.07, 0.004)],
            paint,
            1.0,
        )
        tag(dash, "marking")
    paving = mats.principled("paving_c", albedo="paving_c", roughness=0.45)
    ys = np.arange(-10.0, 140.01, 1.0)
    tag(
        ribbon("pavement_right", line, ys, [(3.5, 0.0), (3.5, 0.13), (5.5, 0.13)], paving, 4.0),
        "sidewalk",
    )
    tag(
        ribbon("pavement_left", line, ys, [(-5.5, 0.13), (-3.5, 0.13), (-3.5, 0.0)], paving, 4.0),
        "sidewalk",
    )
    concrete = mats.principled("board_concrete", albedo="concrete_c", roughness=0.85)
    stone = mats.principled("sandstone", albedo="sandstone", roughness=0.8)
    # the cutting's retaining walls, their tops level at +1.2 m, to the bridge
    wys = np.arange(-10.0, 44.01, 2.0)
    tag(wall("wall_right", wys, 5.5, lambda y: h(y), lambda y: 1.2, concrete, 4.0, -1.0), "wall")
    tag(wall("wall_left", wys, -5.5, lambda y: h(y), lambda y: 1.2, concrete, 4.0, 1.0), "wall")
    # ground above the cutting and buildings set back on it
    ground = mats.principled("ground_c", albedo="paving_c", roughness=0.9)
    for sx in (-1.0, 1.0):
        xa, xb = sorted((sx * 5.5, sx * 40.0))
        tag(box(f"ground_{sx:+.0f}", (xa, -10.0, 0.0), (xb, 44.0, 1.2), ground, 4.0), "terrain")
    # the railway: a sandstone embankment either side, a concrete deck over the road
    deck_lo = low + 4.6
    for sx in (-1.0, 1.0):
        xa, xb = sorted((sx * 5.5, sx * 60.0))
        tag(
            box(
                f"embankment_{sx:+.0f}",
                (xa, 44.0, low - 0.5),
                (xb, 56.0, deck_lo + 1.3),
                stone,
                3.0,
            ),
            "building",
        )
    tag(box("deck", (-5.6, 44.0, deck_lo), (5.6, 56.0, deck_lo + 1.3), concrete, 4.0), "building")
    rail = mats.principled("parapet_steel", (0.1, 0.11, 0.12), roughness=0.5, metallic=0.7)
    for k, (ya, yb) in enumerate(((44.0, 44.3), (55.7, 56.0))):
        tag(
            box(f"parapet{k}", (-60.0, ya, deck_lo + 1.3), (60.0, yb, deck_lo + 2.4), rail),
            "street_furniture",
        )
    # beyond: shop fronts and rendered terraces on both sides, a terrace closing the view
    facades = [
        mats.principled("shopfronts", albedo="shopfronts", roughness=0.7),
        mats.principled("render_c", albedo="render_c", roughness=0.9),
        stone,
    ]
    rng = np.random.default_rng(31)
    k = 0
    for sx in (-1.0, 1.0):
        y = 56.0
        while y < 138.0:
            ln = float(rng.uniform(9.0, 15.0))
            xa, xb = sorted((sx * 5.5, sx * 15.0))
            ht = float(rng.uniform(7.0, 13.0))
            tag(
                box(
                    f"building_{k}",
                    (xa, y, low - 0.5),
                    (xb, y + ln, low + ht),
                    facades[k % 3],
                    8.0 if k % 3 == 0 else 3.0,
                ),
                "building",
            )
            y, k = y + ln, k + 1
    tag(
        box("terrace_end", (-20.0, 140.0, low - 0.5), (20.0, 152.0, low + 12.0), facades[1], 3.0),
        "building",
    )
    for sx in (-1.0, 1.0):
        xa, xb = sorted((sx * 12.0, sx * 25.0))
        for y0 in (-6.0, 14.0):
            tag(
                box(
                    f"house_{sx:+.0f}_{y0:.0f}",
                    (xa, y0, 1.2),
                    (xb, y0 + 15.0, 9.0),
                    facades[1],
                    3.0,
                ),
                "building",
            )
    # lamps: hung over the centre from span wires (cutting and setts street), wall-mounted in
    # the underpass and on the facades beyond
    for j, y in enumerate((6.0, 26.0, 70.0, 94.0, 118.0)):
        top = (h(y) + 7.0) if y < 44.0 else (low + 7.0)
        catenary_lamp(mats, f"span{j}", (-5.5, 5.5), (0.0, y, top), LED_2700, 2200.0)
        for sx in (-1.0, 1.0):
            tag(
                box(
                    f"span{j}_mast{sx:+.0f}",
                    (sx * 5.6 - 0.08, y - 0.08, h(y)),
                    (sx * 5.6 + 0.08, y + 0.08, top + 0.7),
                    mats.principled(
                        "lamp_metal_c", (0.12, 0.12, 0.12), roughness=0.45, metallic=0.6
                    ),
                ),
                "pole",
            )
    for j, (sx, y) in enumerate(((1.0, 47.0), (-1.0, 53.0))):
        wall_lamp(mats, f"underpass{j}", (sx * 5.5, y, low + 3.4), -sx, LED_5700, 1200.0)
    for j, (sx, y) in enumerate(((-1.0, 62.0), (1.0, 82.0), (-1.0, 106.0))):
        wall_lamp(mats, f"facade_lamp{j}", (sx * 5.5, y, low + 5.0), -sx, LED_5700, 1500.0)
    # a car ahead on the descent, an oncoming car in the underpass
    grey = mats.principled(
        "paint_graphite", (0.08, 0.08, 0.09), roughness=0.3, metallic=0.6, coat=1.0
    )
    y = 24.0
    pitch = math.atan(h(y + 0.5) - h(y - 0.5))
    tw = sloped_car(mats, "car_ahead", (1.75, y, h(y)), 0.0, pitch, grey, 1)
    tail_lights(mats, "taillight", tw, 0.0, 1, cd=12.0)
    yellow = mats.principled("paint_yellow", (0.5, 0.35, 0.03), roughness=0.3, coat=1.0)
    tw = car(mats, "oncoming_car", (-1.75, 52.0, low), math.pi, yellow, 2)
    headlights(mats, "headlight", tw, math.pi, 2, colour=LED_5700, cd=13000.0, pitch=1.0)
    eye = (1.75, 0.0, 1.3)
    camera("driver", eye, pitched(np.array([0.0, 1.0, 0.0]), 2.5), 40.0, 704, 396)


def build_hillside(mats: Materials) -> None:
    """A narrow street climbing a hill on a right-hand bend (radius 45 m from 10 m ahead), its
    grade rising from 3 % to 9 % over the first 35 m, the carriageway banked (cross-fall
    3.5 %, falling to the right, the inside of the bend): 5.6 m of running lanes between 2 m
    parking strips, cars parked on both sides, 12 cm kerbs, 1.8 m pavements, shop fronts
    (some lit, warm and cool), rendered and sandstone terraces; warm LED 2200 K lamps on
    wall brackets on the left, cool LED 5700 K lamps on posts on the right; a car coming down
    with its headlights; wet asphalt with few puddles (roughness 0.16, puddles 0.05 on 15 %);
    a truck's camera 2.4 m up."""

    def grade(s: float) -> float:
        return ramp_grade(s, 0.03, 0.09, 35.0)

    line = CentreLine(radius=-45.0, bend_start=10.0, profile=grade)
    fall = 0.035
    ss = np.arange(-8.0, 100.01, 1.0)
    road = mats.principled(
        "wet_asphalt", albedo="asphalt_hill", roughness_map="puddles_hill", road=True
    )
    xs = [(x, -fall * x) for x in np.linspace(-4.8, 4.8, 9)]
    tag(ribbon("road", line, ss, xs, road, 2.0), "road")
    paint = mats.principled("road_paint_c", (0.62, 0.6, 0.5), roughness=0.22, road=True)
    for sx in (-1.0, 1.0):
        x = sx * 2.8
        prof = [(x - 0.06, -fall * x + 0.004), (x + 0.06, -fall * x + 0.004)]
        tag(ribbon(f"edge_line_{sx:+.0f}", line, ss, prof, paint, 1.0), "marking")
    paving = mats.principled("paving_c", albedo="paving_c", roughness=0.45)
    hl, hr = fall * 4.8, -fall * 4.8
    tag(
        ribbon(
            "pavement_left",
            line,
            ss,
            [(-6.6, hl + 0.12), (-4.8, hl + 0.12), (-4.8, hl)],
            paving,
            4.0,
        ),
        "sidewalk",
    )
    tag(
        ribbon(
            "pavement_right", line, ss, [(4.8, hr), (4.8, hr + 0.12), (6.6, hr + 0.12)], paving, 4.0
        ),
        "sidewalk",
    )
    facades = [
        mats.principled("shopfronts", albedo="shopfronts", roughness=0.7),
        mats.principled("render_c", albedo="render_c", roughness=0.9),
        mats.principled("sandstone", albedo="sandstone", roughness=0.8),
    ]
    rng = np.random.default_rng(32)
    shops = []
    for side, x, hb in (("right", 6.6, hr), ("left", -6.6, hl)):
        s0, k = -8.0, 0
        while s0 < 98.0:
            length = float(rng.uniform(7.0, 12.0))
            height = float(rng.uniform(8.0, 13.0))
            seg = np.linspace(s0, min(s0 + length, 100.0), 6)
            prof = (
                [(x, hb - 1.0), (x, hb + height)]
                if side == "right"
                else [(x, hb + height), (x, hb - 1.0)]
            )
            tile = 8.0 if k % 3 == 0 else 3.0
            tag(
                ribbon(f"facade_{side}_{k}", line, seg, prof, facades[k % 3], tile, True),
                "building",
            )
            if k % 3 == 0 and s0 > 0.0:
                shops.append((side, s0 + 0.5 * length, length))
            s0, k = s0 + length, k + 1
    # lit shop windows in the shop-front terraces (every other one warm, the rest cool)
    for j, (side, s, length) in enumerate(shops):
        sx = 1.0 if side == "right" else -1.0
        hb = hr if side == "right" else hl
        foot = line.point(s) + sx * 6.58 * line.right(s) + np.array([0.0, 0.0, hb + 0.12])
        colour, cd_m2 = (SHOP_WARM, 180.0) if j % 2 == 0 else (COOL_WHITE, 120.0)
        mat = mats.principled(
            f"glow_shop{j}", emission=colour, strength=radiance_for_luminance(cd_m2, colour)
        )
        lo, hi = (-0.04, -0.3 * length, 0.4), (0.0, 0.2 * length, 2.4)
        if sx < 0:
            lo, hi = (0.0, -0.3 * length, 0.4), (0.04, 0.2 * length, 2.4)
        place(box(f"shop_window{j}", lo, hi, mat, cls="building"), tuple(foot), line.heading(s))
    # lamps: warm wall lamps on the left facades, cool post lamps on the right pavement
    for j, s in enumerate((8.0, 30.0, 52.0, 74.0)):
        w = line.point(s) - 6.6 * line.right(s) + np.array([0.0, 0.0, hl + 5.5])
        a = line.heading(s)
        metal = mats.principled("lamp_metal_c", (0.12, 0.12, 0.12), roughness=0.45, metallic=0.6)
        bracket = box(
            f"wall_lamp{j}_bracket", (0.0, -0.04, 0.1), (0.8, 0.04, 0.16), metal, cls="pole"
        )
        place(bracket, tuple(w), a)
        head = line.point(s) - 5.75 * line.right(s) + np.array([0.0, 0.0, hl + 5.5])
        lamp_head(mats, f"wall_lamp{j}", tuple(head), (0.4, 0.4), LED_2200, 1600.0)
    for j, s in enumerate((18.0, 42.0, 66.0, 90.0)):
        foot = line.point(s) + 5.9 * line.right(s) + np.array([0.0, 0.0, hr + 0.12])
        street_lamp(mats, f"post_lamp{j}", tuple(foot), line.heading(s), 1.0, LED_5700, 2600.0)
    # parked cars on both strips, a car coming down the hill with its headlights
    paints = [
        mats.principled("paint_cream", (0.55, 0.5, 0.38), roughness=0.3, coat=1.0),
        mats.principled("paint_navy", (0.02, 0.04, 0.12), roughness=0.25, metallic=0.5, coat=1.0),
        mats.principled("paint_red_c", (0.4, 0.04, 0.03), roughness=0.3, coat=1.0),
        mats.principled("paint_grey", (0.25, 0.26, 0.27), roughness=0.35, metallic=0.7),
    ]
    inst = 1
    for sx, spots in (
        (1.0, (7.0, 12.5, 24.0, 36.0, 41.5, 58.0)),
        (-1.0, (10.0, 21.0, 26.5, 44.0, 55.0)),
    ):
        for s in spots:
            x = sx * 3.8
            c = line.point(s) + x * line.right(s) + np.array([0.0, 0.0, -fall * x])
            pitch = math.atan(grade(s + 0.5) - grade(s - 0.5))
            sloped_car(
                mats, f"parked{inst}", tuple(c), line.heading(s), pitch, paints[inst % 4], inst
            )
            inst += 1
    s = 48.0
    x = -1.4
    c = line.point(s) + x * line.right(s) + np.array([0.0, 0.0, -fall * x])
    pitch = math.atan(grade(s + 0.5) - grade(s - 0.5))
    tw = sloped_car(mats, "oncoming", tuple(c), line.heading(s) + math.pi, -pitch, paints[3], inst)
    # it faces downhill: its dipped beams 1.5 degrees below the road, which falls by `pitch`
    headlights(
        mats,
        "headlight",
        tw,
        line.heading(s) + math.pi,
        inst,
        colour=HALOGEN,
        cd=12000.0,
        pitch=1.5 + math.degrees(pitch),
    )
    x = 1.4
    eye = line.point(0.0) + x * line.right(0.0) + np.array([0.0, 0.0, -fall * x + 2.4])
    camera("truck", tuple(eye), pitched(line.along(0.0), 1.0), 40.0, 560, 420)


def build_daylight_street(mats: Materials) -> None:
    """A streak-free street a KITTI user would recognise: a straight residential street in
    sunshine, a dry, rough road (roughness 0.72 +- 0.08, no puddles; flagged as the road),
    crowned by 6 cm, 2 m parking strips with cars on both sides, 12 cm kerbs, 3 m
    pavements with trees, shop fronts, rendered and sandstone facades 9-16 m high, unlit lamp
    posts; a sun of 60 klx (5700 K) 40 degrees up from behind the camera on the left and a
    constant blue sky (3 kcd/m^2); a car ahead, an oncoming car; the camera 1.65 m up."""
    road = mats.principled(
        "dry_asphalt", albedo="asphalt_dry", roughness_map="dry_rough", road=True
    )
    ys = np.arange(-10.0, 161.0, 4.0)
    tag(
        grid("road", np.linspace(-5.0, 5.0, 11), ys, lambda x, y: crown(x, 5.0, 0.06), road, 2.5),
        "road",
    )
    paint = mats.principled("road_paint_dry", (0.7, 0.7, 0.66), roughness=0.7, road=True)
    for k, y in enumerate(np.arange(-6.0, 156.0, 6.0)):
        tag(box(f"centre_dash_{k}", (-0.06, y, 0.055), (0.06, y + 3.0, 0.064), paint), "marking")
    paving = mats.principled("paving_c", albedo="paving_c", roughness=0.8)
    kerb = mats.principled("kerb_c", (0.35, 0.35, 0.33), roughness=0.8)
    facades = [
        mats.principled("shopfronts", albedo="shopfronts", roughness=0.8),
        mats.principled("render_c", albedo="render_c", roughness=0.9),
        mats.principled("sandstone", albedo="sandstone", roughness=0.85),
    ]
    rng = np.random.default_rng(33)
    k = 0
    for sx in (-1.0, 1.0):
        xa, xb = sorted((sx * 5.0, sx * 5.15))
        tag(box(f"kerb_{sx:+.0f}", (xa, -10.0, -0.2), (xb, 160.0, 0.12), kerb), "sidewalk")
        xa, xb = sorted((sx * 5.15, sx * 8.0))
        tag(
            box(f"pavement_{sx:+.0f}", (xa, -10.0, -0.2), (xb, 160.0, 0.12), paving, 4.0),
            "sidewalk",
        )
        y = -10.0
        while y < 158.0:
            ln = float(rng.uniform(10.0, 18.0))
            xa, xb = sorted((sx * 8.0, sx * 20.0))
            ht = float(rng.uniform(9.0, 16.0))
            tag(
                box(
                    f"building_{k}",
                    (xa, y, -0.5),
                    (xb, y + ln, ht),
                    facades[k % 3],
                    8.0 if k % 3 == 0 else 3.0,
                ),
                "building",
            )
            y, k = y + ln, k + 1
        for j, y0 in enumerate(np.arange(4.0, 150.0, 20.0)):
            tree(
                mats,
                f"tree{sx:+.0f}_{j}",
                (sx * 6.6, float(y0) + (10.0 if sx < 0 else 0.0), 0.12),
                float(rng.uniform(5.5, 7.5)),
                False,
                100 + j + (50 if sx > 0 else 0),
                leaves="leaves_c",
            )
    metal = mats.principled("lamp_metal_c", (0.12, 0.12, 0.12), roughness=0.45, metallic=0.6)
    for j, y0 in enumerate(np.arange(10.0, 150.0, 28.0)):
        for sx in (-1.0, 1.0):
            yy = float(y0) + (14.0 if sx < 0 else 0.0)
            tag(
                box(
                    f"post{j}{sx:+.0f}",
                    (sx * 5.5 - 0.07, yy - 0.07, 0.12),
                    (sx * 5.5 + 0.07, yy + 0.07, 7.0),
                    metal,
                ),
                "pole",
            )
            xa, xb = sorted((sx * 5.5, sx * 4.3))
            tag(
                box(f"post{j}{sx:+.0f}_head", (xa, yy - 0.15, 6.85), (xb, yy + 0.15, 7.0), metal),
                "pole",
            )
    paints = [
        mats.principled("paint_silver_c", (0.5, 0.5, 0.52), roughness=0.45, metallic=0.6),
        mats.principled("paint_blue_c", (0.05, 0.12, 0.35), roughness=0.45),
        mats.principled("paint_white_c", (0.7, 0.7, 0.68), roughness=0.5),
        mats.principled("paint_black_c", (0.03, 0.03, 0.03), roughness=0.45),
        mats.principled("paint_red_d", (0.45, 0.05, 0.04), roughness=0.5),
    ]
    inst = 1
    for sx, spots in (
        (1.0, (9.0, 14.5, 27.0, 33.0, 46.0, 60.0, 72.0)),
        (-1.0, (6.0, 18.0, 23.5, 38.0, 52.0, 65.0)),
    ):
        for y in spots:
            car(
                mats,
                f"parked{inst}",
                (sx * 4.0, y, 0.02),
                0.0 if sx > 0 else math.pi,
                paints[inst % 5],
                inst,
            )
            inst += 1
    car(mats, "car_ahead", (1.5, 22.0, 0.05), 0.0, paints[2], inst)
    car(mats, "oncoming", (-1.5, 40.0, 0.05), math.pi, paints[4], inst + 1)
    sun = bpy.data.lights.new("sun", "SUN")
    sun.color = SUN
    sun.energy = watts_for_lux(60000.0, SUN)
    sun.angle = 0.0
    obj = bpy.data.objects.new("sun", sun)
    bpy.context.scene.collection.objects.link(obj)
    # light travelling forwards (+Y), to the right and down: the sun behind-left of the camera
    elev, azim = math.radians(40.0), math.radians(30.0)
    point_along(
        obj, (math.sin(azim) * math.cos(elev), math.cos(azim) * math.cos(elev), -math.sin(elev))
    )
    sky = 3000.0 / 683.0 / luminance(SKY)  # a 3 kcd/m^2 sky, as a radiance factor on SKY
    bpy.context.scene["streaks"] = {"environment": {"color": list(SKY), "strength": sky}}
    camera(
        "camera", (1.5, 0.0, 0.05 + 1.65), pitched(np.array([0.0, 1.0, 0.0]), 1.0), 36.0, 640, 384
    )


# --- the fourth set (made after the first three had been looked at) ---------------------------

#: Fourth set: a mercury-vapour-like bluish white (about 4000 K, its green-blue lines) on the
#: bridge's parapets and LED 3500 K on the square's masts, both linear sRGB, peak 1.
MERCURY = (0.80, 0.94, 1.0)
LED_3500 = (1.0, 0.55, 0.25)
WINDOW_WARM = (1.0, 0.66, 0.32)


def glow_box(mats, name, lo: Vec3, hi: Vec3, colour, cd_m2: float, cls: str):
    """An emissive box (a lit window, a shop window, a tram's windows) of luminance `cd_m2`;
    one material per colour and luminance."""
    mat = mats.principled(
        f"glow_{cd_m2:.0f}_{colour[1]:.2f}",
        emission=colour,
        strength=radiance_for_luminance(cd_m2, colour),
    )
    return box(name, lo, hi, mat, cls=cls)


def post_lamp(mats, name, foot: Vec3, height: float, arms, colour, cd, metal) -> None:
    """A mast standing at `foot` to `height` with a luminaire at the end of each arm: `arms`
    is a list of (dx, dy) reaches from the mast (a head 0.6 x 0.35 m on each)."""
    x, y, z = foot
    tag(
        box(f"{name}_mast", (x - 0.08, y - 0.08, z), (x + 0.08, y + 0.08, z + height), metal),
        "pole",
    )
    for k, (dx, dy) in enumerate(arms):
        xa, xb = sorted((x, x + dx))
        ya, yb = sorted((y, y + dy))
        tag(
            box(
                f"{name}_arm{k}",
                (xa - 0.04, ya - 0.04, z + height - 0.08),
                (xb + 0.04, yb + 0.04, z + height),
                metal,
            ),
            "pole",
        )
        size = (0.6, 0.35) if abs(dx) >= abs(dy) else (0.35, 0.6)
        lamp_head(mats, f"{name}_{k}", (x + dx, y + dy, z + height - 0.2), size, colour, cd)


def bus(mats, name, centre: Vec3, pitch: float, paint, instance: int):
    """A bus (11 x 2.5 x 3.1 m) heading +Y, pitched nose-up by `pitch` radians, a dark rear
    window; returns its local-to-world map (local +Y its front)."""
    body = box(
        f"{name}_body", (-1.25, -5.5, 0.35), (1.25, 5.5, 3.1), paint, cls="bus", inst=instance
    )
    glass = mats.principled("bus_glass", (0.015, 0.015, 0.02), roughness=0.05, coat=1.0)
    rear = box(
        f"{name}_rear_window",
        (-1.1, -5.53, 1.5),
        (1.1, -5.49, 2.8),
        glass,
        cls="bus",
        inst=instance,
    )
    tyre = mats.principled("tyre", (0.02, 0.02, 0.02), roughness=0.9)
    skirt = box(
        f"{name}_wheels", (-1.2, -5.0, 0.0), (1.2, 5.0, 0.35), tyre, cls="bus", inst=instance
    )
    for part in (body, rear, skirt):
        part.location = centre
        part.rotation_euler = (pitch, 0.0, 0.0)
    cp, sp = math.cos(pitch), math.sin(pitch)

    def to_world(p: Vec3) -> Vec3:
        return (
            centre[0] + p[0],
            centre[1] + cp * p[1] - sp * p[2],
            centre[2] + sp * p[1] + cp * p[2],
        )

    return to_world


def build_bridge(mats: Materials) -> None:
    """A two-lane road (7 m) over a river bridge: the deck climbs at 2 % to a crest about 12 m
    ahead, then falls at up to -3.5 % to the far bank (3 m lower, 110 m ahead), where the road
    runs on level between shop fronts and rendered houses. 15 cm kerbs, 1.8 m footways, open
    parapets (a 0.45 m concrete plinth, steel posts every 4 m and a rail at 1.15 m) with lamps
    on both sides every 24 m (mercury-vapour-like bluish white, about 4000 K, 1.9 kcd); the
    river 9 m below; along the far bank's quay a row of blocks of flats with lit windows, facing the
    bridge; a bus ahead on the descent with its tail lights, two oncoming cars (halogen and
    xenon headlights); wet asphalt (roughness 0.12, puddles 0.035 on 30 %); the camera 1.35 m
    up (a car) just short of the crest."""
    far = 110.0

    def h(y: float) -> float:
        return ramp_grade(min(y, far), 0.02, -0.035, 30.0)

    low = h(far)  # about -3 m
    line = straight(h)
    asphalt = mats.principled(
        "wet_asphalt", albedo="asphalt_d", roughness_map="puddles_d", road=True
    )
    xs = [(x, 0.0) for x in np.linspace(-3.5, 3.5, 8)]
    tag(ribbon("road", line, np.arange(-10.0, far + 60.01, 1.0), xs, asphalt, 2.0), "road")
    paint = mats.principled("road_paint_d", (0.6, 0.6, 0.55), roughness=0.25, road=True)
    for k, y0 in enumerate(np.arange(-8.0, far + 50.0, 6.0)):
        dash = ribbon(
            f"centre_dash_{k}",
            line,
            np.linspace(y0, y0 + 3.0, 3),
            [(-0.07, 0.004), (0.07, 0.004)],
            paint,
            1.0,
        )
        tag(dash, "marking")
    footway = mats.principled("footway_d", albedo="slabs", roughness=0.5)
    ys = np.arange(-10.0, far + 60.01, 1.0)
    tag(
        ribbon("footway_right", line, ys, [(3.5, 0.0), (3.5, 0.15), (5.3, 0.15)], footway, 3.0),
        "sidewalk",
    )
    tag(
        ribbon("footway_left", line, ys, [(-5.3, 0.15), (-3.5, 0.15), (-3.5, 0.0)], footway, 3.0),
        "sidewalk",
    )
    # the parapets: a concrete plinth, steel posts every 4 m and a rail, over the river only
    parapet = mats.principled("parapet_d", albedo="parapet_d", roughness=0.85)
    steel = mats.principled("rail_steel_d", (0.16, 0.17, 0.18), roughness=0.35, metallic=0.8)
    bys = np.arange(-10.0, far + 0.01, 2.0)
    tag(
        ribbon("plinth_right", line, bys, [(5.3, 0.15), (5.3, 0.6), (5.6, 0.6)], parapet, 2.0),
        "wall",
    )
    tag(
        ribbon("plinth_left", line, bys, [(-5.6, 0.6), (-5.3, 0.6), (-5.3, 0.15)], parapet, 2.0),
        "wall",
    )
    tag(
        ribbon("rail_right", line, bys, [(5.4, 1.15), (5.5, 1.15), (5.5, 1.05)], steel, 1.0),
        "fence",
    )
    tag(
        ribbon("rail_left", line, bys, [(-5.5, 1.05), (-5.5, 1.15), (-5.4, 1.15)], steel, 1.0),
        "fence",
    )
    for sx in (-1.0, 1.0):
        for k, y in enumerate(np.arange(-9.0, far, 4.0)):
            tag(
                box(
                    f"post_{sx:+.0f}_{k}",
                    (sx * 5.45 - 0.03, y - 0.03, h(y) + 0.6),
                    (sx * 5.45 + 0.03, y + 0.03, h(y) + 1.1),
                    steel,
                ),
                "fence",
            )
    # the deck's edge beams (seen from the far bank's reflections only) and the river
    tag(
        box("deck_beam", (-5.7, -40.0, low - 1.6), (5.7, far, low - 0.4), parapet, 4.0),
        "building",
    )
    water = mats.principled("river", (0.01, 0.012, 0.014), roughness=0.04)
    q = mesh_object(
        "river",
        [(-300.0, -60.0, -9.0), (300.0, -60.0, -9.0), (300.0, far, -9.0), (-300.0, far, -9.0)],
        [(0, 1, 2, 3)],
        [(0, 0), (60, 0), (60, 34), (0, 34)],
        water,
    )
    tag(q, "terrain")
    # the far bank: a quay wall, the bank, a row of flats along the quay facing the bridge
    tag(box("quay", (-300.0, far, -9.5), (300.0, far + 2.0, low - 0.02), parapet, 4.0), "wall")
    ground = mats.principled("bank_d", albedo="parapet_d", roughness=0.8)
    for sx in (-1.0, 1.0):
        xa, xb = sorted((sx * 5.3, sx * 300.0))
        tag(
            box(
                f"bank_{sx:+.0f}", (xa, far + 2.0, -9.5), (xb, far + 90.0, low + 0.15), ground, 4.0
            ),
            "terrain",
        )
    flats = [
        mats.principled("far_flats", albedo="far_flats", roughness=0.85),
        mats.principled("far_flats_b", albedo="far_flats_b", roughness=0.85),
    ]
    rng = np.random.default_rng(83)
    k = 0
    for sx in (-1.0, 1.0):
        x = 9.0
        while x < 160.0:
            wd = float(rng.uniform(14.0, 26.0))
            ht = float(rng.uniform(12.0, 28.0))
            xa, xb = sorted((sx * x, sx * (x + wd)))
            y0 = far + float(rng.uniform(8.0, 14.0))
            tag(
                box(f"flats_{k}", (xa, y0, low), (xb, y0 + 12.0, low + ht), flats[k % 2], 14.0),
                "building",
            )
            # a few lit windows on the face towards the river
            for j in range(int(rng.integers(4, 9))):
                wx = float(rng.uniform(xa + 1.0, xb - 2.2))
                wz = low + 3.5 * int(rng.integers(0, int(ht / 3.5))) + 1.2
                glow_box(
                    mats,
                    f"window_{k}_{j}",
                    (wx, y0 - 0.06, wz),
                    (wx + 1.2, y0 - 0.01, wz + 1.4),
                    WINDOW_WARM,
                    40.0,
                    "building",
                )
            x, k = x + wd + float(rng.uniform(2.0, 6.0)), k + 1
    # the street on the far bank: shop fronts and rendered houses, a terrace closing the view
    shops = mats.principled("shopfronts_d", albedo="shopfronts_d", roughness=0.7)
    render = mats.principled("render_d", albedo="render_d", roughness=0.9)
    for sx in (-1.0, 1.0):
        y = far + 28.0
        while y < far + 86.0:
            ln = float(rng.uniform(8.0, 13.0))
            xa, xb = sorted((sx * 5.3, sx * 16.0))
            ht = float(rng.uniform(7.0, 12.0))
            mat = shops if k % 2 == 0 else render
            tag(
                box(
                    f"house_{k}",
                    (xa, y, low),
                    (xb, y + ln, low + ht),
                    mat,
                    8.0 if k % 2 == 0 else 3.0,
                ),
                "building",
            )
            if k % 2 == 0:
                glow_box(
                    mats,
                    f"shop_{k}",
                    (sx * 5.33 - 0.02, y + 1.0, low + 0.5),
                    (sx * 5.33 + 0.02, y + ln - 2.0, low + 2.6),
                    WINDOW_WARM,
                    120.0,
                    "building",
                )
            y, k = y + ln, k + 1
    tag(
        box("terrace_end", (-25.0, far + 88.0, low), (25.0, far + 100.0, low + 11.0), render, 3.0),
        "building",
    )
    # lamps on the parapets, both sides every 24 m; two on the far bank's street
    metal = mats.principled("lamp_metal_d", (0.2, 0.21, 0.22), roughness=0.4, metallic=0.7)
    for j, y in enumerate(np.arange(6.0, far, 24.0)):
        for sx in (-1.0, 1.0):
            post_lamp(
                mats,
                f"parapet_lamp{j}{'r' if sx > 0 else 'l'}",
                (sx * 5.45, float(y), h(float(y)) + 0.6),
                6.9,
                [(-sx * 1.3, 0.0)],
                MERCURY,
                1900.0,
                metal,
            )
    for j, (sx, y) in enumerate(((1.0, far + 40.0), (-1.0, far + 64.0))):
        post_lamp(
            mats,
            f"bank_lamp{j}",
            (sx * 4.8, y, low + 0.15),
            7.0,
            [(-sx * 1.4, 0.0)],
            MERCURY,
            1900.0,
            metal,
        )
    # a bus ahead on the descent, two oncoming cars
    red = mats.principled("paint_bus_d", (0.35, 0.03, 0.02), roughness=0.35, coat=1.0)
    y = 34.0
    pitch = math.atan(h(y + 0.5) - h(y - 0.5))
    tw = bus(mats, "bus_ahead", (1.75, y, h(y)), pitch, red, 1)
    for k, x in enumerate((-1.0, 1.0)):
        car_light(mats, f"bus_tail{k}", tw, 0.0, (x, -5.5, 0.9), -1.0, RED, 800.0, 11.0, 40.0, 1)
    silver = mats.principled(
        "paint_silver_d", (0.45, 0.46, 0.48), roughness=0.25, metallic=0.8, coat=1.0
    )
    for k, (y, colour, cd) in enumerate(((66.0, HALOGEN, 14000.0), (98.0, XENON, 15000.0))):
        up = -math.atan(h(y + 0.5) - h(y - 0.5))  # nose-up climbing towards the crest
        tw = sloped_car(mats, f"oncoming{k}", (-1.75, y, h(y)), math.pi, up, silver, 2 + k)
        headlights(
            mats,
            f"headlight{k}_",
            tw,
            math.pi,
            2 + k,
            colour=colour,
            cd=cd,
            pitch=1.2 - math.degrees(up),
        )
    eye = (1.75, 0.0, h(0.0) + 1.35)
    camera("driver", eye, pitched(np.array([0.0, 1.0, 0.0]), 1.5), 36.0, 768, 384)


def build_square(mats: Materials) -> None:
    """A street opening into a wide level town square (60 x 42 m) and crossed in it by
    another street carrying a double tram track; no roundabout, a plain junction. The
    approach and the far street are wet asphalt (roughness 0.14, small puddles 0.03 on 20 %);
    in the square the carriageways are paved with large granite-like slabs, wet (about 0.09,
    water in the joints 0.03), flagged as road; the pedestrian plaza the same slabs, rougher,
    8 cm up. Shop fronts all round (lit windows, warm), rendered upper storeys; LED 3500 K
    luminaires (2.6-3 kcd) on 8-10 m masts, one to four heads each; a car ahead entering the
    square with its tail lights, a car on the cross street with xenon headlights, a tram past
    the junction with lit windows, an oncoming car in the far street; the camera 1.0 m up (a
    low car) 6 m before the approach's buildings end."""
    asphalt = mats.principled(
        "wet_asphalt", albedo="asphalt_sq", roughness_map="puddles_sq", road=True
    )
    slabs = mats.principled("wet_slabs", albedo="slabs", roughness_map="slabs_wet", road=True)
    plaza = mats.principled("plaza_slabs", albedo="slabs", roughness=0.32)
    level = lambda s: 0.0  # noqa: E731
    xs = [(x, 0.0) for x in np.linspace(-3.5, 3.5, 8)]
    line = straight(level)
    tag(ribbon("road", line, np.arange(-10.0, 24.01, 1.0), xs, asphalt, 2.0), "road")
    tag(ribbon("road_far", line, np.arange(66.0, 150.01, 2.0), xs, asphalt, 2.0), "road")
    tag(ribbon("road_square", line, np.arange(24.0, 66.01, 1.0), xs, slabs, 3.0), "road")
    flat = lambda x, y: 0.0  # noqa: E731
    for k, (xa, xb) in enumerate(((-30.0, -3.5), (3.5, 30.0))):
        tag(
            grid(
                f"cross_square{k}",
                np.arange(xa, xb + 0.01, (xb - xa) / 12),
                [41.0, 48.0],
                flat,
                slabs,
                3.0,
            ),
            "road",
        )
    for k, (xa, xb) in enumerate(((-90.0, -30.0), (30.0, 90.0))):
        tag(
            grid(f"cross_street{k}", np.linspace(xa, xb, 13), [41.0, 48.0], flat, asphalt, 2.0),
            "road",
        )
    # the tram's double track along the cross street
    steel = mats.principled("tram_rail", (0.3, 0.3, 0.32), roughness=0.2, metallic=0.9)
    for k, y in enumerate((42.3, 43.7, 45.3, 46.7)):
        tag(box(f"rail{k}", (-90.0, y - 0.035, 0.0), (90.0, y + 0.035, 0.006), steel), "rail_track")
    # the plaza (8 cm up), pavements along the approach and the far street
    for k, (xa, xb, ya, yb) in enumerate(
        (
            (-30.0, -3.5, 24.0, 41.0),
            (3.5, 30.0, 24.0, 41.0),
            (-30.0, -3.5, 48.0, 66.0),
            (3.5, 30.0, 48.0, 66.0),
        )
    ):
        tag(box(f"plaza{k}", (xa, ya, -0.2), (xb, yb, 0.08), plaza, 3.0), "sidewalk")
    for sx in (-1.0, 1.0):
        for k, (ya, yb) in enumerate(((-10.0, 24.0), (66.0, 150.0))):
            xa, xb = sorted((sx * 3.5, sx * 6.0))
            tag(
                box(f"pavement_{sx:+.0f}_{k}", (xa, ya, -0.2), (xb, yb, 0.12), plaza, 3.0),
                "sidewalk",
            )
        for k, (ya, yb) in enumerate(((34.0, 41.0), (48.0, 55.0))):
            xa, xb = sorted((sx * 30.0, sx * 90.0))
            tag(
                box(f"cross_pavement_{sx:+.0f}_{k}", (xa, ya, -0.2), (xb, yb, 0.12), plaza, 3.0),
                "sidewalk",
            )
    # buildings all round: shop fronts on the ground floor, rendered above
    shops = mats.principled("shopfronts_d", albedo="shopfronts_d", roughness=0.7)
    render = mats.principled("render_d", albedo="render_d", roughness=0.9)
    blocks = [
        (-16.0, -6.0, -10.0, 12.0, -1.0),  # approach, left (faces +X)
        (6.0, 16.0, -10.0, 12.0, 1.0),
        (-30.0, -6.0, 12.0, 24.0, 0.0),  # the square's near side (faces +Y)
        (6.0, 30.0, 12.0, 24.0, 0.0),
        (-42.0, -30.0, 24.0, 34.0, -1.0),  # west and east sides (face the square)
        (-42.0, -30.0, 55.0, 66.0, -1.0),
        (30.0, 42.0, 24.0, 34.0, 1.0),
        (30.0, 42.0, 55.0, 66.0, 1.0),
        (-30.0, -6.0, 66.0, 78.0, 2.0),  # the far side (faces -Y)
        (6.0, 30.0, 66.0, 78.0, 2.0),
        (-16.0, -6.0, 78.0, 150.0, -1.0),  # the far street
        (6.0, 16.0, 78.0, 150.0, 1.0),
        (-20.0, 20.0, 150.0, 160.0, 2.0),
    ]
    rng = np.random.default_rng(91)
    for k, (xa, xb, ya, yb, face) in enumerate(blocks):
        ground_h = 4.2
        top = float(rng.uniform(10.0, 17.0))
        tag(box(f"shops_{k}", (xa, ya, -0.3), (xb, yb, ground_h), shops, 8.5), "building")
        tag(box(f"upper_{k}", (xa, ya, ground_h), (xb, yb, top), render, 3.0), "building")
        # lit shop windows on the face towards the street or the square
        if face == 0.0:
            continue
        if abs(face) == 1.0:  # facing +-X: the face at the inner x
            x = xb if face < 0 else xa
            step = 9.0
            for j, y in enumerate(np.arange(ya + 1.5, yb - 4.0, step)):
                if rng.uniform() < 0.35:
                    continue
                glow_box(
                    mats,
                    f"shopwin_{k}_{j}",
                    (x - 0.03, float(y), 0.6),
                    (x + 0.03, float(y) + 4.0, 2.9),
                    WINDOW_WARM if j % 3 else COOL_WHITE,
                    150.0,
                    "building",
                )
        else:  # facing -Y: the face at ya
            for j, x in enumerate(np.arange(xa + 1.5, xb - 4.0, 7.0)):
                if rng.uniform() < 0.3:
                    continue
                glow_box(
                    mats,
                    f"shopwin_{k}_{j}",
                    (float(x), ya - 0.03, 0.6),
                    (float(x) + 4.0, ya + 0.03, 2.9),
                    WINDOW_WARM if j % 2 else COOL_WHITE,
                    150.0,
                    "building",
                )
    # lamps on tall masts
    metal = mats.principled("lamp_metal_sq", (0.1, 0.1, 0.11), roughness=0.5, metallic=0.6)
    masts = [
        ("approach_l", (-4.6, 6.0), 8.0, [(1.2, 0.0)], 2600.0),
        ("approach_r", (4.6, 18.0), 8.0, [(-1.2, 0.0)], 2600.0),
        ("corner_sw", (-5.2, 37.0), 9.0, [(1.2, 0.0), (0.0, 1.2)], 2800.0),
        ("corner_ne", (5.2, 52.0), 9.0, [(-1.2, 0.0), (0.0, -1.2)], 2800.0),
        (
            "plaza_w",
            (-17.0, 58.0),
            10.0,
            [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)],
            3000.0,
        ),
        ("plaza_e", (17.0, 30.0), 10.0, [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)], 3000.0),
        ("far_l", (-4.6, 92.0), 8.0, [(1.2, 0.0)], 2600.0),
        ("far_r", (4.6, 116.0), 8.0, [(-1.2, 0.0)], 2600.0),
    ]
    for name, (x, y), ht, arms, cd in masts:
        post_lamp(mats, f"mast_{name}", (x, y, 0.08), ht, arms, LED_3500, cd, metal)
    # a car ahead entering the square, a car on the cross street, a tram, an oncoming car
    blue = mats.principled("paint_blue_d", (0.03, 0.06, 0.2), roughness=0.3, coat=1.0)
    tw = car(mats, "car_ahead", (1.75, 27.0, 0.0), 0.0, blue, 1)
    tail_lights(mats, "taillight", tw, 0.0, 1, cd=10.0)
    white = mats.principled("paint_white_d", (0.6, 0.6, 0.58), roughness=0.3, coat=1.0)
    tw = car(mats, "cross_car", (-13.0, 42.75, 0.0), -math.pi / 2, white, 2)
    headlights(mats, "cross_headlight", tw, -math.pi / 2, 2, colour=XENON, cd=14000.0)
    green = mats.principled("paint_tram_d", (0.05, 0.18, 0.08), roughness=0.35, coat=1.0)
    box("tram_body", (8.0, 45.2, 0.35), (38.0, 47.8, 3.4), green, cls="train", inst=3)
    glow_box(mats, "tram_windows", (9.0, 45.15, 1.3), (37.0, 45.19, 2.6), COOL_WHITE, 90.0, "train")
    grey = mats.principled("paint_grey_d", (0.2, 0.2, 0.21), roughness=0.3, metallic=0.5, coat=1.0)
    tw = car(mats, "oncoming_car", (-1.75, 96.0, 0.0), math.pi, grey, 4)
    headlights(mats, "headlight", tw, math.pi, 4, colour=HALOGEN, cd=14000.0)
    eye = (1.75, 6.0, 1.0)
    camera("driver", eye, pitched(np.array([0.0, 1.0, 0.0]), 1.0), 40.0, 600, 400)


# --- the fifth set (made after the first four had been looked at) ----------------------------

#: Fifth set's lamp colours, linear sRGB of their blackbodies (peak 1): high-pressure sodium
#: at about 2000 K (warmer than the first sets' near-sRGB-encoded HPS), a cold LED at 6000 K
#: (quay walls, headlights) and a neutral LED at 4500 K (the arterial's median columns).
SODIUM_2000 = (1.0, 0.27, 0.02)
LED_6000 = (1.0, 0.90, 0.86)
LED_4500 = (1.0, 0.71, 0.49)
SIGN_GREEN = (0.05, 0.45, 0.2)


def van(mats, name, centre: Vec3, heading: float, paint, instance: int):
    """A box van (5.6 x 2.0 x 2.5 m) heading along its local +Y: a tall load box, a cab with a
    dark windscreen, a skirt of wheels; returns the local-to-world map."""
    body = box(f"{name}_body", (-1.0, -2.8, 0.35), (1.0, 1.6, 2.5), paint, cls="car", inst=instance)
    cab = box(f"{name}_cab", (-1.0, 1.6, 0.35), (1.0, 2.8, 1.3), paint, cls="car", inst=instance)
    glass = mats.principled("van_glass_e", (0.02, 0.02, 0.025), roughness=0.05, coat=1.0)
    screen = box(
        f"{name}_screen", (-0.95, 1.6, 1.3), (0.95, 2.3, 2.0), glass, cls="car", inst=instance
    )
    tyre = mats.principled("tyre", (0.02, 0.02, 0.02), roughness=0.9)
    skirt = box(
        f"{name}_wheels", (-0.95, -2.5, 0.0), (0.95, 2.5, 0.35), tyre, cls="car", inst=instance
    )
    for part in (body, cab, screen, skirt):
        place(part, centre, heading)

    def to_world(p: Vec3) -> Vec3:
        c, s = math.cos(heading), math.sin(heading)
        return (centre[0] + c * p[0] - s * p[1], centre[1] + s * p[0] + c * p[1], centre[2] + p[2])

    return to_world


def build_quay(mats: Materials) -> None:
    """A harbour-side street: a straight two-way street (6.5 m) of wet basalt cobbles (stones
    about 0.3, water in the joints 0.07, puddles of 0.03 on a fifth where the paving has sunk;
    flagged as road, material `wet_cobbles`) falling 2.5 % across towards the harbour on its
    left; on the left a 4.7 m quay promenade of flags ending at a low granite quay wall (0.75
    m) over the dark water of the basin 2.6 m below, which ends 130 m ahead at a far quay with
    a row of warehouses whose lit windows face the street; on the right a 2.2 m pavement and
    brick warehouses 9-15 m high with a few lit windows and a lit pub window. Lamps at varying
    heights: high-pressure sodium (2000 K, 2 kcd) on 9 m posts on the promenade reaching over
    the road, cold LED lanterns (6000 K, 600 cd) on 3.6 m posts on the quay wall, cold LED
    wall lamps (6000 K, 1.1-1.4 kcd) on the warehouses at 4.2-5.5 m. A white van parked at
    the right kerb, a car ahead with its tail lights, an oncoming car with cold LED
    headlights (13 kcd); the camera 1.25 m above the road in the right lane."""
    cobbles = mats.principled(
        "wet_cobbles", albedo="cobbles_e", roughness_map="cobbles_wet_e", road=True
    )
    fall = 0.025  # across, falling to the left (the harbour side)
    line = straight(lambda s: 0.0)
    xs = [(float(x), fall * float(x)) for x in np.linspace(-3.25, 3.25, 8)]
    tag(ribbon("road", line, np.arange(-10.0, 210.01, 1.0), xs, cobbles, 2.0), "road")
    left_edge, right_edge = -3.25 * fall, 3.25 * fall
    # the promenade and the quay wall over the basin, as far as the basin's head (130 m)
    head = 130.0
    flags = mats.principled("quay_flags_e", albedo="flags_e", roughness=0.35)
    stone = mats.principled("quay_stone_e", albedo="quay_stone_e", roughness=0.7)
    top = left_edge + 0.13
    tag(box("kerb_left", (-3.4, -10.0, -0.5), (-3.25, 210.0, top), stone, 1.0), "sidewalk")
    tag(box("promenade", (-7.95, -10.0, -0.5), (-3.4, head, top), flags, 2.0), "sidewalk")
    tag(box("quay_face", (-8.25, -10.0, -3.5), (-7.95, head, top), stone, 2.0), "wall")
    tag(box("quay_wall", (-8.25, -10.0, top), (-7.95, head, top + 0.75), stone, 2.0), "wall")
    water = mats.principled("harbour_water_e", (0.008, 0.01, 0.012), roughness=0.03)
    q = mesh_object(
        "basin",
        [(-300.0, -60.0, -2.6), (-8.25, -60.0, -2.6), (-8.25, head, -2.6), (-300.0, head, -2.6)],
        [(0, 1, 2, 3)],
        [(0, 0), (73, 0), (73, 47), (0, 47)],
        water,
    )
    tag(q, "terrain")
    # the basin's head: a quay across, and the left side of the street beyond it
    tag(box("head_quay", (-300.0, head, -3.5), (-3.4, head + 40.0, top), flags, 2.0), "sidewalk")
    tag(box("head_face", (-300.0, head - 0.3, -3.5), (-8.25, head, top), stone, 2.0), "wall")
    tag(box("head_wall", (-300.0, head - 0.3, top), (-8.25, head, top + 0.75), stone, 2.0), "wall")
    ware = mats.principled("warehouse_e", albedo="warehouse_e", roughness=0.85)
    far = mats.principled("far_quay_e", albedo="far_quay_e", roughness=0.85)
    rng = np.random.default_rng(113)
    x, k = -9.0, 0
    while x > -220.0:
        wd = float(rng.uniform(16.0, 30.0))
        ht = float(rng.uniform(8.0, 16.0))
        y0 = head + float(rng.uniform(6.0, 10.0))
        tag(
            box(f"far_shed_{k}", (x - wd, y0, top), (x, y0 + 20.0, top + ht), far, 12.0), "building"
        )
        for j in range(int(rng.integers(3, 8))):
            wx = float(rng.uniform(x - wd + 1.0, x - 2.5))
            wz = top + 3.2 * int(rng.integers(0, max(1, int(ht / 3.2)))) + 1.0
            glow_box(
                mats,
                f"far_window_{k}_{j}",
                (wx, y0 - 0.06, wz),
                (wx + 1.4, y0 - 0.01, wz + 1.5),
                WINDOW_WARM if j % 3 else COOL_WHITE,
                35.0,
                "building",
            )
        x, k = x - wd - float(rng.uniform(3.0, 12.0)), k + 1
    # the right side: a pavement and brick warehouses with gaps between them
    ptop = right_edge + 0.14
    tag(box("kerb_right", (3.25, -10.0, -0.5), (3.4, 210.0, ptop), stone, 1.0), "sidewalk")
    tag(box("pavement_right", (3.4, -10.0, -0.5), (5.45, 210.0, ptop), flags, 2.0), "sidewalk")
    y = -10.0
    while y < 200.0:
        ln = float(rng.uniform(14.0, 28.0))
        ht = float(rng.uniform(9.0, 15.0))
        tag(box(f"warehouse_{k}", (5.45, y, -0.3), (20.0, y + ln, ht), ware, 6.0), "building")
        for j in range(int(rng.integers(1, 4))):
            wy = float(rng.uniform(y + 1.0, y + ln - 2.0))
            wz = 3.4 * int(rng.integers(1, max(2, int(ht / 3.4)))) + 0.9
            glow_box(
                mats,
                f"window_{k}_{j}",
                (5.41, wy, wz),
                (5.44, wy + 1.1, wz + 1.4),
                WINDOW_WARM,
                25.0,
                "building",
            )
        y, k = y + ln + float(rng.uniform(0.0, 6.0)), k + 1
    # the left side beyond the basin's head: sheds set back 3 m behind the pavement
    tag(
        box("shed_left", (-40.0, head + 3.0, top), (-6.4, 200.0, top + 10.0), ware, 6.0), "building"
    )
    tag(box("street_end", (-40.0, 205.0, -0.3), (40.0, 215.0, 14.0), ware, 6.0), "building")
    glow_box(
        mats, "pub_window", (5.41, 62.0, 0.6), (5.44, 66.5, 2.6), WINDOW_WARM, 140.0, "building"
    )
    # lamps at varying heights
    metal = mats.principled("lamp_metal_e", (0.07, 0.08, 0.08), roughness=0.45, metallic=0.7)
    for j, y in enumerate((8.0, 40.0, 72.0, 104.0, 136.0, 168.0)):
        post_lamp(
            mats, f"quay_post{j}", (-3.9, y, top), 9.0, [(1.6, 0.0)], SODIUM_2000, 2000.0, metal
        )
    for j, y in enumerate((24.0, 56.0, 88.0, 120.0)):
        post_lamp(
            mats, f"lantern{j}", (-7.75, y, top + 0.75), 2.85, [(0.45, 0.0)], LED_6000, 600.0, metal
        )
    for j, (y, z, cd) in enumerate(((18.0, 5.5, 1400.0), (60.0, 4.2, 1100.0), (92.0, 5.5, 1400.0))):
        wall_lamp(mats, f"wall_lamp{j}", (5.45, y, z), -1.0, LED_6000, cd)
    # a van parked at the right kerb, a car ahead, an oncoming car
    white = mats.principled("paint_van_e", (0.55, 0.56, 0.55), roughness=0.35, coat=0.5)
    van(mats, "parked_van", (2.25, 28.0, right_edge - 0.02), 0.0, white, 1)
    dark_red = mats.principled("paint_red_e", (0.2, 0.02, 0.02), roughness=0.3, coat=1.0)
    tw = car(mats, "car_ahead", (1.45, 48.0, 0.03), 0.0, dark_red, 2)
    tail_lights(mats, "taillight", tw, 0.0, 2, cd=12.0)
    black = mats.principled("paint_black_e", (0.02, 0.02, 0.022), roughness=0.25, coat=1.0)
    tw = car(mats, "oncoming_car", (-1.6, 82.0, -0.04), math.pi, black, 3)
    headlights(mats, "headlight", tw, math.pi, 3, colour=LED_6000, cd=13000.0, pitch=1.0)
    eye = (1.3, 0.0, fall * 1.3 + 1.25)
    camera("driver", eye, pitched(np.array([0.0, 1.0, 0.0]), 1.2), 38.0, 656, 368)


def build_arterial(mats: Materials) -> None:
    """A wide divided arterial road: two 7.3 m carriageways (two 3.65 m lanes each, a 1 m
    hard shoulder) either side of a 2.4 m median with a 0.9 m concrete barrier; it falls
    downhill (grade from -1.5 % at the camera to -4 % from 50 m on) and bends left on a 350 m
    radius from 45 m ahead, superelevated to 5 % (rising to the right) over 45-85 m. Twin-arm
    lamp columns on the median barrier every 36 m (12 m, neutral LED 4500 K, 3.2 kcd a head);
    an overhead sign gantry 40 m ahead with two lit green direction signs over our
    carriageway; steel guardrails, grass verges rising into a shallow cutting, a few
    industrial units with lit windows beyond; two cars ahead with tail lights, four oncoming
    cars on the far carriageway with halogen and cold LED headlights (13-15 kcd); wet asphalt
    (roughness 0.1, puddles 0.025 on 22 %); an SUV's camera 1.5 m above the road in the
    nearside lane."""

    def h(s: float) -> float:
        return ramp_grade(s, -0.015, -0.04, 50.0)

    def bank(s: float) -> float:
        return 0.05 * smoothstep((s - 45.0) / 40.0)

    line = CentreLine(radius=350.0, bend_start=45.0, profile=h)
    ss = np.arange(-10.0, 260.01, 2.0)

    def at(s: float, x: float, up: float = 0.0) -> Vec3:
        p = line.point(s) + x * line.right(s)
        return (float(p[0]), float(p[1]), float(p[2] + bank(s) * x + up))

    asphalt = mats.principled(
        "wet_asphalt", albedo="asphalt_e", roughness_map="puddles_e", road=True
    )
    xs = [(float(x), 0.0) for x in np.linspace(-9.5, 9.5, 20)]
    tag(ribbon("road", line, ss, xs, asphalt, 2.0, bank=bank), "road")
    # markings: lane dashes (3 m every 12 m), edge lines by the shoulders and the median
    paint = mats.principled("road_paint_e", (0.62, 0.62, 0.6), roughness=0.3, road=True)
    for sx in (-1.0, 1.0):
        for k, s0 in enumerate(np.arange(-9.0, 255.0, 12.0)):
            x = sx * 4.85
            dash = ribbon(
                f"dash_{sx:+.0f}_{k}",
                line,
                np.linspace(s0, s0 + 3.0, 3),
                [(x - 0.08, 0.004), (x + 0.08, 0.004)],
                paint,
                1.0,
                bank=bank,
            )
            tag(dash, "marking")
        for k, x in enumerate((sx * 1.35, sx * 8.5)):
            lo, hi = sorted((x - 0.1, x + 0.1))
            tag(
                ribbon(
                    f"edge_{sx:+.0f}_{k}",
                    line,
                    ss,
                    [(lo, 0.004), (hi, 0.004)],
                    paint,
                    1.0,
                    bank=bank,
                ),
                "marking",
            )
    # the median barrier (a concrete safety-shape wall)
    barrier = mats.principled("barrier_e", albedo="barrier_e", roughness=0.8)
    shape = [(-0.3, 0.0), (-0.2, 0.25), (-0.12, 0.9), (0.12, 0.9), (0.2, 0.25), (0.3, 0.0)]
    tag(ribbon("median_barrier", line, ss, shape, barrier, 1.0, bank=bank), "wall")
    # guardrails and verges rising into a shallow cutting
    steel = mats.principled("guardrail_e", (0.3, 0.31, 0.32), roughness=0.3, metallic=0.8)
    grass = mats.principled("verge_e", albedo="verge_e", roughness=0.9)
    for sx in (-1.0, 1.0):
        x = sx * 9.9
        lo, hi = sorted((x - 0.02 * sx, x))
        rail = [(lo, 0.45), (lo, 0.78)] if sx > 0 else [(hi, 0.78), (hi, 0.45)]
        tag(ribbon(f"guardrail_{sx:+.0f}", line, ss, rail, steel, 1.0, bank=bank), "fence")
        for k, s in enumerate(np.arange(-8.0, 250.0, 4.0)):
            c = at(float(s), sx * 9.95)
            post = box(f"rail_post_{sx:+.0f}_{k}", (-0.04, -0.04, -0.1), (0.04, 0.04, 0.75), steel)
            tag(place(post, c, line.heading(float(s))), "fence")
        verge = [(9.5, 0.0), (12.0, 0.1), (18.0, 2.0), (40.0, 3.0)]
        if sx < 0:
            verge = [(-x_, h_) for x_, h_ in reversed(verge)]
        tag(ribbon(f"verge_{sx:+.0f}", line, ss, verge, grass, 2.0, bank=bank), "terrain")
    # industrial units beyond the verges, a few lit windows
    units = mats.principled("units_e", albedo="far_quay_e", roughness=0.85)
    rng = np.random.default_rng(131)
    for k, (s, sx, d) in enumerate(
        (
            (70.0, 1.0, 45.0),
            (120.0, 1.0, 55.0),
            (170.0, 1.0, 40.0),
            (150.0, -1.0, 60.0),
            (215.0, -1.0, 45.0),
            (240.0, 1.0, 50.0),
        )
    ):
        c = at(s, sx * d, 3.0)
        heading = line.heading(s)
        wd, dp, ht = (float(v) for v in rng.uniform((20.0, 12.0, 7.0), (40.0, 20.0, 12.0)))
        tag(
            place(
                box(f"unit_{k}", (-dp / 2, -wd / 2, -1.0), (dp / 2, wd / 2, ht), units, 12.0),
                c,
                heading,
            ),
            "building",
        )
        for j in range(int(rng.integers(2, 6))):
            wy = float(rng.uniform(-wd / 2 + 1.0, wd / 2 - 2.5))
            wz = float(rng.uniform(1.0, ht - 2.5))
            fx = -sx * (dp / 2 + 0.03)
            win = glow_box(
                mats,
                f"unit_window_{k}_{j}",
                (fx - 0.02, wy, wz),
                (fx + 0.02, wy + 2.0, wz + 1.2),
                WINDOW_WARM if j % 2 else COOL_WHITE,
                60.0,
                "building",
            )
            place(win, c, heading)
    # twin-arm lamp columns on the median barrier
    metal = mats.principled("lamp_metal_e", (0.07, 0.08, 0.08), roughness=0.45, metallic=0.7)
    for j, s in enumerate(np.arange(12.0, 250.0, 36.0)):
        s = float(s)
        r = line.right(s)
        arms = [(float(2.3 * r[0]), float(2.3 * r[1])), (float(-2.3 * r[0]), float(-2.3 * r[1]))]
        post_lamp(mats, f"column{j}", at(s, 0.0, 0.9), 11.1, arms, LED_4500, 3200.0, metal)
    # the sign gantry 40 m ahead (the road is straight and unbanked there)
    sg = 40.0
    zg = h(sg)
    for k, x in enumerate((-10.6, 10.6)):
        tag(
            box(
                f"gantry_leg{k}",
                (x - 0.2, sg - 0.2, zg - 0.2),
                (x + 0.2, sg + 0.2, zg + 7.4),
                steel,
            ),
            "pole",
        )
    tag(box("gantry_truss", (-10.8, sg - 0.5, zg + 6.4), (10.8, sg + 0.5, zg + 7.4), steel), "pole")
    for k, (xa, xb) in enumerate(((1.6, 4.9), (5.1, 8.4))):
        glow_box(
            mats,
            f"sign{k}",
            (xa, sg - 0.62, zg + 4.6),
            (xb, sg - 0.52, zg + 6.9),
            SIGN_GREEN,
            30.0,
            "traffic_sign",
        )
        glow_box(
            mats,
            f"sign_text{k}",
            (xa + 0.4, sg - 0.66, zg + 5.6),
            (xb - 0.4, sg - 0.62, zg + 6.0),
            COOL_WHITE,
            90.0,
            "traffic_sign",
        )

    # traffic: two cars ahead, four oncoming on the far carriageway
    def slope(s: float) -> float:
        return math.atan(h(s + 0.5) - h(s - 0.5))

    blue = mats.principled("paint_blue_e", (0.02, 0.05, 0.15), roughness=0.3, coat=1.0)
    silver = mats.principled(
        "paint_silver_e", (0.4, 0.41, 0.43), roughness=0.25, metallic=0.8, coat=1.0
    )
    for k, (s, x) in enumerate(((52.0, 3.0), (118.0, 6.7))):
        tw = sloped_car(
            mats, f"ahead{k}", at(s, x), line.heading(s), slope(s), blue if k else silver, 1 + k
        )
        tail_lights(mats, f"tail{k}_", tw, line.heading(s), 1 + k, cd=11.0)
    white = mats.principled("paint_white_e", (0.62, 0.62, 0.6), roughness=0.3, coat=1.0)
    for k, (s, x, colour) in enumerate(
        (
            (64.0, -3.0, HALOGEN),
            (100.0, -6.7, LED_6000),
            (148.0, -3.0, LED_6000),
            (196.0, -6.7, HALOGEN),
        )
    ):
        up = -slope(s)  # climbing towards the camera
        heading = line.heading(s) + math.pi
        tw = sloped_car(
            mats, f"oncoming{k}", at(s, x), heading, up, white if k % 2 else silver, 3 + k
        )
        headlights(
            mats,
            f"headlight{k}_",
            tw,
            heading,
            3 + k,
            colour=colour,
            cd=13000.0 + 700.0 * k,
            pitch=1.2 - math.degrees(up),
        )
    eye = at(0.0, 6.7, 1.5)
    camera("driver", eye, pitched(np.array([0.0, 1.0, 0.0]), 1.9), 32.0, 720, 360)


# --- the sixth set (made after the first five had been looked at) ----------------------------

#: Sixth set's light colours, linear sRGB of their blackbodies (peak 1, about; Tanner
#: Helland's fit of the sRGB values, linearised): a neutral LED at 4200 K on the tramway's
#: catenary poles, a warm LED at 2400 K along the road past the forecourt, a cold LED at
#: 5000 K in the forecourt's canopy panels; the forecourt's blue brand colour.
LED_4200 = (1.0, 0.644, 0.429)
LED_2400 = (1.0, 0.328, 0.045)
PANEL_5000 = (1.0, 0.77, 0.62)
BRAND_BLUE = (0.02, 0.12, 0.9)
AMBER = (1.0, 0.45, 0.03)


def tram(mats, name, centre: Vec3, heading: float, pitch: float, paint, instance: int):
    """A tram (30 x 2.65 x 3.5 m, one rigid body) whose front is along its local +Y, pitched
    nose-up by `pitch`: a dark skirt, a body with lit windows down both sides (60 cd/m2), a
    dark windscreen, an amber destination display (150 cd/m2), a pantograph reaching 5.88 m
    up; returns the local-to-world map."""
    glass = mats.principled("tram_glass_f", (0.015, 0.015, 0.02), roughness=0.05, coat=1.0)
    skirt = mats.principled("tram_skirt_f", (0.03, 0.03, 0.035), roughness=0.6)
    metal = mats.principled("pantograph_f", (0.1, 0.1, 0.1), roughness=0.4, metallic=0.8)
    parts = [
        box(
            f"{name}_body",
            (-1.32, -15.0, 0.45),
            (1.32, 15.0, 3.5),
            paint,
            cls="train",
            inst=instance,
        ),
        box(
            f"{name}_skirt",
            (-1.25, -14.5, 0.1),
            (1.25, 14.5, 0.45),
            skirt,
            cls="train",
            inst=instance,
        ),
        box(
            f"{name}_screen",
            (-1.2, 14.99, 1.2),
            (1.2, 15.03, 2.9),
            glass,
            cls="train",
            inst=instance,
        ),
        box(
            f"{name}_pantograph",
            (-0.5, -0.05, 3.5),
            (0.5, 0.05, 5.88),
            metal,
            cls="train",
            inst=instance,
        ),
    ]
    for sx in (-1.0, 1.0):
        lo, hi = sorted((sx * 1.32, sx * 1.35))
        parts.append(
            glow_box(
                mats,
                f"{name}_windows{sx:+.0f}",
                (lo, -13.5, 1.3),
                (hi, 13.0, 2.5),
                COOL_WHITE,
                60.0,
                "train",
            )
        )
    parts.append(
        glow_box(
            mats, f"{name}_display", (-0.8, 15.0, 3.0), (0.8, 15.05, 3.35), AMBER, 150.0, "train"
        )
    )
    for part in parts:
        part.location = centre
        part.rotation_euler = (pitch, 0.0, heading)
        tag(part, "train", instance)
    return sloped_to_world(centre, heading, pitch)


def build_tramway(mats: Materials) -> None:
    """An old town's tram street: a 10 m carriageway of wet asphalt (roughness 0.14, puddles
    0.03 on 28 %) with a double tram track set into it (grooved rails flush with the surface,
    track centres 3.2 m apart, the cars sharing the tracks), level for 10 m, then climbing
    gently (to 2.5 % at 50 m) and bending left (R 140 m) from 60 m ahead; 3.4 m pavements of
    flags, a terrace of shops on both sides (half the shop windows lit, warm and cool, 40-70
    cd/m2) under rendered and brick upper storeys with some lit windows. The overhead line:
    poles at both kerbs every 30 m carrying span wires and two contact wires over the track
    centres (5.9 m), and on every other pole, staggered, a neutral LED 4200 K luminaire (2.4
    kcd, 8 m) on a 1.8 m bracket. A tram stop's shelter on the right pavement 36-44 m ahead,
    lit from inside (a diffuser under its roof, 350 cd/m2, and an advert panel, 300 cd/m2);
    a zebra crossing; a car ahead with tail lights, an oncoming tram on the left track
    (front 30 m ahead, lit windows, LED headlights 9 kcd), a van parked at the left kerb;
    the camera 1.4 m above the road in the right lane (a saloon)."""

    def h(s: float) -> float:
        return ramp_grade(s - 10.0, 0.0, 0.025, 40.0) if s > 10.0 else 0.0

    line = CentreLine(radius=140.0, bend_start=60.0, profile=h)
    ss = np.arange(-10.0, 230.01, 1.0)
    half, walk = 5.0, 3.4

    def at(s: float, x: float, up: float = 0.0) -> Vec3:
        p = line.point(s) + x * line.right(s)
        return (float(p[0]), float(p[1]), float(p[2] + up))

    asphalt = mats.principled(
        "wet_asphalt", albedo="asphalt_f", roughness_map="puddles_f", road=True
    )
    xs = [(float(x), 0.0) for x in np.linspace(-half, half, 11)]
    tag(ribbon("road", line, ss, xs, asphalt, 2.0), "road")
    # the double track: rail heads of wet steel and the water-filled grooves inside them
    steel = mats.principled("rail_steel_f", (0.42, 0.42, 0.44), roughness=0.12, metallic=1.0)
    groove = mats.principled("rail_groove_f", (0.01, 0.01, 0.012), roughness=0.05)
    gauge, head_w, groove_w = 1.435, 0.06, 0.04
    for t, tc in enumerate((-1.6, 1.6)):
        for side in (-1.0, 1.0):
            inner = tc + side * gauge / 2.0
            for part, (a, b), mat in (
                ("head", (inner, inner + side * head_w), steel),
                ("groove", (inner - side * groove_w, inner), groove),
            ):
                lo, hi = sorted((a, b))
                rail = ribbon(
                    f"rail_{part}_{t}_{side:+.0f}", line, ss, [(lo, 0.002), (hi, 0.002)], mat, 1.0
                )
                tag(rail, "rail_track")
    # a zebra crossing 14-17 m ahead
    paint = mats.principled("road_paint_f", (0.6, 0.6, 0.58), roughness=0.35, road=True)
    for k, x in enumerate(np.arange(-4.5, 4.0, 1.0)):
        stripe = ribbon(
            f"zebra_{k}",
            line,
            np.linspace(14.0, 17.0, 3),
            [(x, 0.004), (x + 0.5, 0.004)],
            paint,
            1.0,
        )
        tag(stripe, "marking")
    # kerbs and pavements
    flags = mats.principled("flags_f", albedo="flags_f", roughness=0.4)
    kerb = 0.13
    left = [(-half - walk, kerb), (-half, kerb), (-half, 0.0)]
    right = [(half, 0.0), (half, kerb), (half + walk, kerb)]
    for k, prof in enumerate((left, right)):
        tag(ribbon(f"pavement{k}", line, ss, prof, flags, 2.0), "sidewalk")
    # terraces: shop fronts on the ground floor, rendered or brick upper storeys
    shops = mats.principled("shopfronts_f", albedo="shopfronts_f", roughness=0.7)
    uppers = (
        (mats.principled("render_f", albedo="render_f", roughness=0.9), 6.0, (0.9, 2.4)),
        (mats.principled("bricks_f", albedo="bricks_f", roughness=0.85), 3.0, (1.125, 2.175)),
    )
    rng = np.random.default_rng(141)
    ground = 6.0
    for sx in (-1.0, 1.0):
        s0, k = -10.0, 0
        while s0 < 222.0:
            ln = float(rng.uniform(7.0, 13.0))
            sm = s0 + ln / 2.0
            c, heading = at(sm, sx * (half + walk), kerb), line.heading(sm)
            xa, xb = sorted((0.0, sx * 12.0))
            top = float(rng.uniform(10.0, 17.0))
            mat, tile, (z0, z1) = uppers[int(rng.integers(0, 2))]
            parts = [
                box(f"shops_{sx:+.0f}_{k}", (xa, -ln / 2, -0.5), (xb, ln / 2, ground), shops, 12.0),
                box(f"upper_{sx:+.0f}_{k}", (xa, -ln / 2, ground), (xb, ln / 2, top), mat, tile),
            ]
            # lit shop windows where the texture has its glazing (3 m shops, glass 0.18-1.98 m
            # along, 0.96-4.8 m up), lit upper windows where it has its panes (1.5 m bays)
            fa, fb = sorted((0.0, -sx * 0.04))
            for j in range(math.floor(-ln / 6.0), math.ceil(ln / 6.0)):
                y0 = 3.0 * j + 0.18
                if y0 < -ln / 2 or y0 + 1.8 > ln / 2 or rng.uniform() < 0.5:
                    continue
                colour = (WINDOW_WARM, COOL_WHITE, SHOP_WARM)[int(rng.integers(0, 3))]
                cd = (40.0, 70.0)[int(rng.integers(0, 2))]
                parts.append(
                    glow_box(
                        mats,
                        f"shopwin_{sx:+.0f}_{k}_{j}",
                        (fa, y0, 0.96),
                        (fb, y0 + 1.8, 4.8),
                        colour,
                        cd,
                        "building",
                    )
                )
            for j in range(math.floor(-ln / 3.0), math.ceil(ln / 3.0)):
                y0 = 1.5 * j + 0.45
                if y0 < -ln / 2 or y0 + 0.6 > ln / 2:
                    continue
                for st in range(int((top - ground) // 3.0)):
                    if rng.uniform() > 0.18:
                        continue
                    z = ground + 3.0 * st
                    parts.append(
                        glow_box(
                            mats,
                            f"win_{sx:+.0f}_{k}_{j}_{st}",
                            (fa, y0, z + z0),
                            (fb, y0 + 0.6, z + z1),
                            WINDOW_WARM,
                            25.0,
                            "building",
                        )
                    )
            for part in parts:
                place(part, c, heading)
                tag(part, "building")
            s0, k = s0 + ln, k + 1
    # the overhead line: poles at both kerbs every 30 m, span wires, contact wires
    metal = mats.principled("pole_metal_f", (0.09, 0.1, 0.1), roughness=0.45, metallic=0.7)
    wire = mats.principled("wire_f", (0.05, 0.05, 0.05), roughness=0.4, metallic=0.8)
    for j, s in enumerate(np.arange(4.0, 200.0, 30.0)):
        s = float(s)
        r = line.right(s)
        for sx in (-1.0, 1.0):
            foot = at(s, sx * (half + 0.5), kerb)
            lit = (j % 2 == 0) == (sx < 0)  # staggered: left on even poles, right on odd
            if lit:
                arm = (float(-sx * 1.8 * r[0]), float(-sx * 1.8 * r[1]))
                post_lamp(mats, f"pole{j}_{sx:+.0f}", foot, 8.0, [arm], LED_4200, 2400.0, metal)
            else:
                mast = box(f"pole{j}_{sx:+.0f}_mast", (-0.08, -0.08, 0.0), (0.08, 0.08, 7.2), metal)
                tag(place(mast, foot, line.heading(s)), "pole")
        span = box(f"span{j}", (-half - 0.5, -0.01, 6.6), (half + 0.5, 0.01, 6.62), wire)
        tag(place(span, at(s, 0.0), line.heading(s)), "pole")
    for t, tc in enumerate((-1.6, 1.6)):
        contact = ribbon(
            f"contact_wire{t}", line, ss, [(tc + 0.008, 5.9), (tc - 0.008, 5.9)], wire, 1.0
        )
        tag(contact, "pole")
    # the tram stop's shelter on the right pavement, lit from inside
    shelter_metal = mats.principled("shelter_f", (0.25, 0.26, 0.27), roughness=0.4, metallic=0.6)
    shelter_glass = mats.principled(
        "shelter_glass_f", (0.02, 0.022, 0.025), roughness=0.05, coat=1.0
    )
    c, heading = at(40.0, 0.0, kerb), line.heading(40.0)
    xo = half + 1.5
    parts = [
        box("shelter_roof", (xo - 0.2, -3.7, 2.5), (xo + 1.8, 3.7, 2.62), shelter_metal),
        box("shelter_back", (xo + 1.5, -3.5, 0.15), (xo + 1.55, 3.5, 2.5), shelter_glass),
        box("shelter_bench", (xo + 1.0, -2.0, 0.45), (xo + 1.45, 2.0, 0.5), shelter_metal),
    ]
    for k, (x, y) in enumerate(((xo, -3.5), (xo, 3.5), (xo + 1.5, -3.5), (xo + 1.5, 3.5))):
        parts.append(
            box(
                f"shelter_post{k}",
                (x - 0.04, y - 0.04, 0.0),
                (x + 0.04, y + 0.04, 2.5),
                shelter_metal,
            )
        )
    for part in parts:
        tag(place(part, c, heading), "street_furniture")
    for part in (
        glow_box(
            mats,
            "shelter_light",
            (xo + 0.3, -3.0, 2.47),
            (xo + 1.2, 3.0, 2.5),
            COOL_WHITE,
            350.0,
            "street_furniture",
        ),
        glow_box(
            mats,
            "shelter_advert",
            (xo + 0.05, 3.44, 0.25),
            (xo + 1.45, 3.5, 2.05),
            COOL_WHITE,
            300.0,
            "street_furniture",
        ),
    ):
        place(part, c, heading)

    # traffic: a car ahead, an oncoming tram on the left track, a van parked at the left kerb
    def slope(s: float) -> float:
        return math.atan(h(s + 0.5) - h(s - 0.5))

    blue = mats.principled("paint_blue_f", (0.03, 0.07, 0.18), roughness=0.3, coat=1.0)
    tw = sloped_car(mats, "car_ahead", at(22.0, 2.4), 0.0, slope(22.0), blue, 1)
    tail_lights(mats, "taillight", tw, 0.0, 1, cd=12.0)
    cream = mats.principled("paint_tram_f", (0.55, 0.5, 0.38), roughness=0.35, coat=1.0)
    tw = tram(mats, "tram", at(45.0, -1.6), math.pi, -slope(45.0), cream, 2)
    for k, x in enumerate((-0.9, 0.9)):
        car_light(
            mats,
            f"tram_headlight{k}",
            tw,
            math.pi,
            (x, 15.0, 0.95),
            1.0,
            LED_6000,
            25000.0,
            9000.0,
            20.0,
            2,
            pitch_deg=1.5,
        )
    white = mats.principled("paint_van_f", (0.5, 0.5, 0.48), roughness=0.35, coat=0.5)
    van(mats, "parked_van", at(92.0, -half + 1.05), line.heading(92.0) + math.pi, white, 3)
    eye = at(0.0, 2.3, 1.4)
    camera("driver", eye, pitched(np.array([0.0, 1.0, 0.0]), 1.5), 36.0, 688, 400)


def build_forecourt(mats: Materials) -> None:
    """A petrol station's forecourt at night by a dark country road: 44 x 56 m of flat wet
    concrete in 5 m panels with oil stains (roughness 0.2, puddles 0.035 on 35 %; flagged as
    road, material `wet_concrete`), painted parking bays on the apron's right, along the left
    edge and before the shop; a canopy (26 x 12 m, its underside 5.2 m up) with a blue lit
    fascia and fifteen square LED panels (5000 K, 4 kcd each) over three pump islands (six
    pumps with lit displays); a shop with a lit glass front and a car wash behind; a price
    sign lit on both faces by the exit. Beyond, a two-lane road of wet asphalt (roughness
    0.12, puddles 0.025 on 30 %; flagged as road too) with warm LED 2400 K lamps (1.8 kcd,
    8 m) along its far verge, a hedge, a dark field and a few houses with lit windows; a car
    at a pump, a car in a bay, a car leaving with its tail lights, two cars on the road
    (xenon and halogen headlights, 13-14 kcd); a van's camera 1.85 m up on the apron 20 m
    before the canopy."""
    concrete = mats.principled(
        "wet_concrete", albedo="concrete_f", roughness_map="concrete_wet_f", road=True
    )
    asphalt = mats.principled(
        "wet_asphalt", albedo="asphalt_road_f", roughness_map="puddles_road_f", road=True
    )
    flat = lambda x, y: 0.0  # noqa: E731
    tag(
        grid(
            "forecourt",
            np.linspace(-22.0, 22.0, 23),
            np.linspace(-12.0, 44.0, 29),
            flat,
            concrete,
            10.0,
        ),
        "road",
    )
    tag(
        grid("road", np.linspace(-160.0, 160.0, 81), [44.0, 48.5, 53.0], flat, asphalt, 2.0), "road"
    )
    # painted bays, the give-way line at the exit, the road's centre line
    paint = mats.principled("bay_paint_f", (0.62, 0.62, 0.6), roughness=0.35, road=True)
    marks = []
    for y in np.arange(-2.0, 20.01, 2.5):
        marks.append(((-21.5, y - 0.06), (-16.5, y + 0.06)))
    marks.append(((-16.56, -2.0), (-16.44, 20.0)))
    for y in np.arange(-6.0, 6.51, 2.5):  # bays on the apron's right, by the entrance
        marks.append(((7.5, y - 0.06), (12.5, y + 0.06)))
    for x in np.arange(-21.0, -3.99, 2.5):
        marks.append(((x - 0.06, 22.5), (x + 0.06, 27.0)))
    for x in np.arange(-21.5, 21.5, 1.0):
        marks.append(((x, 43.4), (x + 0.6, 43.7)))
    for x in np.arange(-150.0, 150.0, 9.0):
        marks.append(((x, 48.42), (x + 3.0, 48.58)))
    for k, ((xa, ya), (xb, yb)) in enumerate(marks):
        tag(box(f"mark{k}", (xa, ya, 0.0), (xb, yb, 0.004), paint), "marking")
    # verges, the hedge, the field and houses beyond the road
    grass = mats.principled("field_f", albedo="field_f", roughness=0.9)
    for k, (xa, xb, ya, yb) in enumerate(
        ((-160.0, -22.0, -40.0, 44.0), (22.0, 160.0, -40.0, 44.0), (-160.0, 160.0, 53.0, 56.0))
    ):
        tag(box(f"verge{k}", (xa, ya, -0.5), (xb, yb, 0.12), grass, 3.0), "terrain")
    tag(
        grid(
            "field",
            np.linspace(-300.0, 300.0, 13),
            np.linspace(56.0, 400.0, 9),
            lambda x, y: 0.1 + 0.004 * (y - 56.0),
            grass,
            3.0,
        ),
        "terrain",
    )
    hedge = mats.principled("hedge_f", albedo="field_f", roughness=0.95)
    tag(box("hedge", (-160.0, 55.0, 0.1), (160.0, 56.0, 1.4), hedge, 2.0), "vegetation")
    houses = mats.principled("houses_f", albedo="houses_f", roughness=0.85)
    rng = np.random.default_rng(151)
    for k, x in enumerate((-95.0, -52.0, -30.0, 18.0, 47.0, 110.0)):
        y = float(rng.uniform(85.0, 130.0))
        wd, dp, ht = (float(v) for v in rng.uniform((8.0, 7.0, 5.5), (14.0, 10.0, 8.0)))
        z = 0.1 + 0.004 * (y - 56.0)
        tag(
            box(f"house{k}", (x - wd / 2, y, z - 0.5), (x + wd / 2, y + dp, z + ht), houses, 8.0),
            "building",
        )
        for j in range(int(rng.integers(1, 4))):
            wx = float(rng.uniform(x - wd / 2 + 0.8, x + wd / 2 - 2.0))
            wz = z + (1.0 if rng.uniform() < 0.5 else 3.8)
            glow_box(
                mats,
                f"house_window{k}_{j}",
                (wx, y - 0.05, wz),
                (wx + 1.2, y - 0.01, wz + 1.3),
                WINDOW_WARM,
                30.0,
                "building",
            )
    for k, x in enumerate((-70.0, -58.0, 36.0, 64.0, 75.0)):
        tree(
            mats,
            f"tree{k}",
            (x, 58.0 + 2.0 * k, 0.1),
            float(rng.uniform(7.0, 11.0)),
            k % 2 == 0,
            20 + k,
            leaves="field_f",
        )
    # the road's lamps along its far verge
    metal = mats.principled("lamp_metal_f", (0.08, 0.08, 0.09), roughness=0.45, metallic=0.7)
    for j, x in enumerate(np.arange(-104.0, 100.0, 32.0)):
        post_lamp(
            mats,
            f"road_lamp{j}",
            (float(x), 53.6, 0.12),
            8.0,
            [(0.0, -1.6)],
            LED_2400,
            1800.0,
            metal,
        )
    # the canopy: a deck with a lit blue fascia, fifteen LED panels, columns on the islands
    deck = mats.principled("canopy_f", (0.55, 0.56, 0.57), roughness=0.5, metallic=0.3)
    tag(box("canopy", (-13.0, 10.0, 5.2), (13.0, 22.0, 6.1), deck), "building")
    glow_box(
        mats, "fascia", (-13.02, 9.97, 5.45), (13.02, 9.99, 5.85), BRAND_BLUE, 45.0, "building"
    )
    for i, x in enumerate((-10.0, -5.0, 0.0, 5.0, 10.0)):
        for j, y in enumerate((12.5, 16.0, 19.5)):
            lamp_head(mats, f"canopy_panel{i}{j}", (x, y, 5.05), (1.3, 1.3), PANEL_5000, 4000.0)
    island = mats.principled("island_f", (0.35, 0.35, 0.34), roughness=0.6)
    column = mats.principled("column_f", (0.6, 0.6, 0.6), roughness=0.4, metallic=0.2)
    pump = mats.principled("pump_f", (0.55, 0.55, 0.56), roughness=0.35, coat=0.5)
    for i, x in enumerate((-8.0, 0.0, 8.0)):
        tag(box(f"island{i}", (x - 0.7, 12.0, 0.0), (x + 0.7, 20.0, 0.16), island), "sidewalk")
        for j, y in enumerate((12.5, 19.5)):
            tag(
                box(f"column{i}{j}", (x - 0.2, y - 0.2, 0.16), (x + 0.2, y + 0.2, 5.2), column),
                "pole",
            )
        for j, y in enumerate((14.6, 17.4)):
            tag(
                box(f"pump{i}{j}", (x - 0.35, y - 0.5, 0.16), (x + 0.35, y + 0.5, 2.0), pump),
                "street_furniture",
            )
            tag(
                box(f"pump_top{i}{j}", (x - 0.38, y - 0.55, 2.0), (x + 0.38, y + 0.55, 2.3), deck),
                "street_furniture",
            )
            for sx in (-1.0, 1.0):
                lo, hi = sorted((x + sx * 0.35, x + sx * 0.37))
                glow_box(
                    mats,
                    f"pump_display{i}{j}{sx:+.0f}",
                    (lo, y - 0.25, 1.3),
                    (hi, y + 0.25, 1.6),
                    COOL_WHITE,
                    80.0,
                    "street_furniture",
                )
    # the shop and the car wash behind the canopy
    cladding = mats.principled("cladding_f", albedo="cladding_f", roughness=0.6)
    tag(box("shop", (-21.0, 27.0, 0.0), (-3.0, 37.0, 4.6), cladding, 8.0), "building")
    glow_box(
        mats, "shop_front", (-19.5, 26.96, 0.3), (-6.0, 27.0, 3.0), COOL_WHITE, 160.0, "building"
    )
    glow_box(
        mats, "shop_sign", (-18.0, 26.95, 3.5), (-8.0, 26.99, 4.2), BRAND_BLUE, 60.0, "building"
    )
    tag(box("car_wash", (9.0, 29.0, 0.0), (20.0, 40.0, 4.2), cladding, 8.0), "building")
    glow_box(mats, "car_wash_sign", (11.0, 28.95, 3.2), (15.0, 28.99, 3.8), AMBER, 90.0, "building")
    # the price sign by the exit, lit on both faces
    tag(box("price_sign", (15.0, 41.0, 0.0), (17.0, 41.5, 6.4), deck), "traffic_sign")
    glow_box(
        mats, "price_logo", (15.2, 40.95, 5.0), (16.8, 41.55, 6.0), BRAND_BLUE, 80.0, "traffic_sign"
    )
    glow_box(
        mats,
        "price_panel",
        (15.3, 40.95, 2.8),
        (16.7, 41.55, 4.8),
        COOL_WHITE,
        120.0,
        "traffic_sign",
    )
    # a car at a pump, a car leaving, two cars on the road
    silver = mats.principled(
        "paint_silver_f", (0.4, 0.41, 0.43), roughness=0.25, metallic=0.8, coat=1.0
    )
    car(mats, "car_at_pump", (-4.0, 16.0, 0.0), 0.0, silver, 1)
    green = mats.principled("paint_green_f", (0.03, 0.12, 0.06), roughness=0.3, coat=1.0)
    car(mats, "car_in_bay", (10.2, 0.25, 0.0), -math.pi / 2, green, 5)
    red = mats.principled("paint_red_f", (0.25, 0.02, 0.02), roughness=0.3, coat=1.0)
    tw = car(mats, "car_leaving", (4.0, 30.0, 0.0), 0.0, red, 2)
    tail_lights(mats, "taillight", tw, 0.0, 2, cd=12.0)
    white = mats.principled("paint_white_f", (0.62, 0.62, 0.6), roughness=0.3, coat=1.0)
    tw = car(mats, "road_car_west", (18.0, 50.7, 0.0), math.pi / 2, white, 3)
    headlights(mats, "headlight_w", tw, math.pi / 2, 3, colour=XENON, cd=14000.0)
    tail_lights(mats, "taillight_w", tw, math.pi / 2, 3, cd=10.0)
    black = mats.principled("paint_black_f", (0.02, 0.02, 0.022), roughness=0.25, coat=1.0)
    tw = car(mats, "road_car_east", (-26.0, 46.3, 0.0), -math.pi / 2, black, 4)
    headlights(mats, "headlight_e", tw, -math.pi / 2, 4, colour=HALOGEN, cd=13000.0)
    tail_lights(mats, "taillight_e", tw, -math.pi / 2, 4, cd=10.0)
    eye = (2.0, -12.0 + 2.0, 1.85)
    camera("driver", eye, pitched(np.array([0.0, 1.0, 0.0]), 2.5), 40.0, 600, 336)


# --- the seventh set (made after the first six had been looked at) ----------------------------

#: Seventh set, linear sRGB near their blackbody, peak 1: warm-white high-mast floodlights
#: (3300 K), the close's single LED lamp (3800 K); lane signals' green and a motorway sign's
#: blue.
MAST_3300 = (1.0, 0.52, 0.23)
LED_3800 = (1.0, 0.58, 0.34)
SIGNAL_GREEN = (0.05, 1.0, 0.3)
SIGN_BLUE = (0.03, 0.12, 0.55)


def high_mast(mats, name, foot: Vec3, height: float, heads: int, colour, cd, metal) -> None:
    """A high mast at `foot`: a tapering-looking square column to `height` and a ring of
    `heads` luminaires (`lamp_head`s of 0.7 x 0.7 m, `cd` each, pointing down) 1.2 m out."""
    x, y, z = foot
    tag(box(f"{name}_mast", (x - 0.3, y - 0.3, z), (x + 0.3, y + 0.3, z + height), metal), "pole")
    tag(
        box(
            f"{name}_ring",
            (x - 1.5, y - 1.5, z + height),
            (x + 1.5, y + 1.5, z + height + 0.25),
            metal,
        ),
        "pole",
    )
    for k in range(heads):
        a = 2.0 * math.pi * (k + 0.5) / heads
        centre = (x + 1.2 * math.cos(a), y + 1.2 * math.sin(a), z + height - 0.2)
        lamp_head(mats, f"{name}_{k}", centre, (0.7, 0.7), colour, cd)


def gantry(mats, name, y: float, x_span: tuple[float, float], z: float, metal) -> None:
    """A sign gantry across the road at `y`: two legs at the ends of `x_span` and a truss
    (a 0.8 x 0.8 m box) whose underside is `z` metres up."""
    xa, xb = x_span
    for k, x in enumerate((xa, xb)):
        tag(
            box(f"{name}_leg{k}", (x - 0.25, y - 0.25, 0.0), (x + 0.25, y + 0.25, z + 0.8), metal),
            "pole",
        )
    tag(box(f"{name}_truss", (xa, y - 0.4, z), (xb, y + 0.4, z + 0.8), metal), "pole")


def build_toll_plaza(mats: Materials) -> None:
    """A motorway toll plaza at night: a level expanse, 68 m wide, of wet asphalt (roughness
    0.11, puddles 0.03 on a quarter; flagged as road) carrying both directions, a 0.8 m
    concrete barrier between them up to the booths; on our side eight toll lanes between nine
    booth islands 80-96 m ahead (eight more for the other direction), each island a kiosk
    with lit windows (60 cd/m2) under a small roof with an LED 5700 K downlight (1.2 kcd),
    and over our lanes' entries a gantry of lane signals (green for open lanes, red for the
    two closed ones, 250 cd/m2); a sign gantry 50 m ahead with three lit blue direction signs
    (15 cd/m2, white lettering 40 cd/m2); five high masts (26 m, a ring of four warm-white
    3300 K floodlights of 6 kcd each) at the plaza's edges and on the barrier's end; an admin
    building with lit windows, grass verges and trees beyond. Many lights: six cars queueing
    ahead with their tail lights (two braking, 60 cd), seven cars on the left that have paid
    and drive towards us, 38-150 m ahead, with halogen, xenon and LED headlights (12-15
    kcd); a saloon's camera 1.45 m up in a lane of the approach, looking at the booths."""
    asphalt = mats.principled(
        "wet_asphalt", albedo="asphalt_g", roughness_map="puddles_g", road=True
    )
    tag(
        grid(
            "plaza",
            np.linspace(-34.0, 34.0, 35),
            np.linspace(-10.0, 210.0, 45),
            lambda x, y: -0.01 * abs(x + 2.5) / 34.0,
            asphalt,
            2.0,
        ),
        "road",
    )
    paint = mats.principled("road_paint_g", (0.62, 0.62, 0.6), roughness=0.35, road=True)
    islands = [-1.0 + 3.8 * k for k in range(9)]
    marks = []
    for x in (2.8, 6.6):  # the approach's lane lines, dashed, until the lanes fan out
        for y in np.arange(2.0, 60.0, 9.0):
            marks.append(((x - 0.07, y), (x + 0.07, y + 3.0)))
    for y in np.arange(0.0, 200.0, 6.0):  # the edge of the carriageway on our right
        marks.append(((31.5, y), (31.65, y + 6.0)))
    for k, ((xa, ya), (xb, yb)) in enumerate(marks):
        tag(box(f"mark{k}", (xa, ya, -0.02), (xb, yb, 0.004), paint), "marking")
    # the barrier between the directions, up to the booths
    barrier = mats.principled("barrier_g", (0.25, 0.25, 0.24), roughness=0.7)
    tag(box("barrier", (-2.85, -10.0, 0.0), (-2.15, 76.0, 0.8), barrier, 2.0), "wall")
    # the booth islands: ours at islands, the other direction's mirrored to the left
    island = mats.principled("island_g", (0.45, 0.44, 0.4), roughness=0.6)
    kiosk = mats.principled("kiosk_g", albedo="booth_g", roughness=0.55)
    roof = mats.principled("kiosk_roof_g", (0.5, 0.52, 0.55), roughness=0.4, metallic=0.5)
    xs = islands + [-4.0 - 3.8 * k for k in range(8)]
    for k, x in enumerate(xs):
        tag(box(f"island{k}", (x - 0.9, 80.0, 0.0), (x + 0.9, 96.0, 0.2), island), "sidewalk")
        tag(box(f"kiosk{k}", (x - 0.7, 86.0, 0.2), (x + 0.7, 89.0, 2.8), kiosk, 3.0), "building")
        for sx in (-1.0, 1.0):
            lo, hi = sorted((x + sx * 0.7, x + sx * 0.72))
            glow_box(
                mats,
                f"kiosk_window{k}{sx:+.0f}",
                (lo, 86.4, 1.1),
                (hi, 88.6, 2.2),
                COOL_WHITE,
                60.0,
                "building",
            )
        tag(box(f"kiosk_roof{k}", (x - 1.2, 84.5, 3.4), (x + 1.2, 90.5, 3.7), roof), "building")
        lamp_head(mats, f"booth_light{k}", (x, 87.5, 3.35), (0.5, 0.5), LED_5700, 1200.0)
    # the lane signals over our lanes' entries, and the plaza's sign gantry
    metal = mats.principled("gantry_g", (0.35, 0.36, 0.37), roughness=0.45, metallic=0.7)
    gantry(mats, "signal_gantry", 78.0, (-2.0, 31.0), 6.0, metal)
    for k in range(8):
        x = (islands[k] + islands[k + 1]) / 2.0
        colour = RED if k in (0, 6) else SIGNAL_GREEN
        glow_box(
            mats,
            f"lane_signal{k}",
            (x - 0.35, 77.55, 5.2),
            (x + 0.35, 77.6, 5.9),
            colour,
            250.0,
            "traffic_light",
        )
    gantry(mats, "sign_gantry", 50.0, (-1.5, 31.5), 6.5, metal)
    for k, (xa, xb) in enumerate(((0.5, 8.5), (11.0, 19.0), (21.5, 29.5))):
        glow_box(
            mats, f"sign{k}", (xa, 49.5, 7.3), (xb, 49.55, 9.8), SIGN_BLUE, 15.0, "traffic_sign"
        )
        glow_box(
            mats,
            f"sign_text{k}",
            (xa + 1.0, 49.45, 8.2),
            (xb - 1.0, 49.5, 8.9),
            COOL_WHITE,
            40.0,
            "traffic_sign",
        )
    # the high masts at the edges and on the barrier's end
    mast = mats.principled("mast_g", (0.3, 0.3, 0.31), roughness=0.5, metallic=0.6)
    for k, (x, y) in enumerate(
        ((33.0, 22.0), (-36.0, 40.0), (-2.5, 70.0), (33.0, 110.0), (-36.0, 130.0))
    ):
        high_mast(mats, f"high_mast{k}", (x, y, 0.0), 26.0, 4, MAST_3300, 6000.0, mast)
    # verges, trees and the admin building beyond
    grass = mats.principled("verge_g", albedo="verge_g", roughness=0.9)
    for k, (xa, xb) in enumerate(((-300.0, -34.0), (34.0, 300.0))):
        tag(box(f"verge{k}", (xa, -40.0, -0.6), (xb, 400.0, 0.05), grass, 3.0), "terrain")
    tag(box("verge_end", (-34.0, 210.0, -0.6), (34.0, 400.0, 0.05), grass, 3.0), "terrain")
    ware = mats.principled("admin_g", albedo="booth_g", roughness=0.7)
    tag(box("admin", (42.0, 84.0, 0.0), (62.0, 98.0, 7.0), ware, 4.0), "building")
    for j in range(5):
        glow_box(
            mats,
            f"admin_window{j}",
            (41.96, 85.5 + 2.4 * j, 1.2 + 3.0 * (j % 2)),
            (41.99, 87.0 + 2.4 * j, 2.6 + 3.0 * (j % 2)),
            WINDOW_WARM,
            30.0,
            "building",
        )
    rng = np.random.default_rng(171)
    for k in range(14):
        side = -1.0 if k % 2 else 1.0
        x = side * float(rng.uniform(40.0, 80.0))
        y = float(rng.uniform(110.0, 300.0)) if k > 3 else float(rng.uniform(0.0, 70.0))
        tree(
            mats,
            f"tree{k}",
            (x, y, 0.05),
            float(rng.uniform(8.0, 14.0)),
            k % 3 == 0,
            40 + k,
            leaves="verge_g",
        )
    # cars queueing ahead (tail lights, two braking), cars leaving on the left, oncoming
    paints = [
        mats.principled("paint_white_g", (0.6, 0.6, 0.58), roughness=0.3, coat=1.0),
        mats.principled("paint_grey_g", (0.15, 0.16, 0.17), roughness=0.25, metallic=0.6, coat=1.0),
        mats.principled("paint_red_g", (0.22, 0.02, 0.02), roughness=0.3, coat=1.0),
        mats.principled("paint_blue_g", (0.02, 0.05, 0.16), roughness=0.3, coat=1.0),
    ]
    queue = (
        (4.7, 24.0, 12.0),
        (0.9, 42.0, 60.0),
        (8.5, 58.0, 11.0),
        (12.3, 71.0, 12.0),
        (4.7, 74.0, 60.0),
        (16.1, 69.0, 10.0),
    )
    for k, (x, y, cd) in enumerate(queue):
        tw = car(mats, f"queue_car{k}", (x, y, 0.0), 0.0, paints[k % 4], 1 + k)
        tail_lights(mats, f"queue_tail{k}", tw, 0.0, 1 + k, cd=cd)
    oncoming = (
        (-5.5, 38.0, HALOGEN, 13000.0),
        (-9.5, 58.0, XENON, 15000.0),
        (-13.5, 72.0, LED_6000, 14000.0),
        (-7.0, 104.0, HALOGEN, 12000.0),
        (-17.3, 100.0, XENON, 14000.0),
        (-9.0, 150.0, LED_6000, 13000.0),
        (-21.1, 118.0, HALOGEN, 13000.0),
    )
    for k, (x, y, colour, cd) in enumerate(oncoming):
        inst = 10 + k
        tw = car(mats, f"oncoming_car{k}", (x, y, 0.0), math.pi, paints[(k + 1) % 4], inst)
        headlights(mats, f"oncoming_head{k}", tw, math.pi, inst, colour=colour, cd=cd, pitch=1.0)
    eye = (4.7, 0.0, 1.45)
    camera("driver", eye, pitched(np.array([0.0, 1.0, 0.0]), 1.2), 30.0, 784, 352)


def porch(mats, name, door: Vec3, facing: float, lit: bool, cd: float) -> None:
    """A house's porch at `door` (the foot of the door in the front wall, which faces +X when
    `facing` = +1): a dark door, a small canopy, and when `lit` a porch lantern beside the door
    (a warm glowing box and a point light of `cd` candela 0.25 m out from the wall)."""
    x, y, z = door
    wood_ = mats.principled("door_g", (0.12, 0.05, 0.03), roughness=0.5, coat=0.5)
    lo, hi = sorted((x, x + facing * 0.05))
    tag(box(f"{name}_door", (lo, y - 0.5, z), (hi, y + 0.5, z + 2.1), wood_), "building")
    lo, hi = sorted((x, x + facing * 0.9))
    canopy_ = mats.principled("porch_roof_g", (0.15, 0.15, 0.16), roughness=0.6)
    tag(box(f"{name}_canopy", (lo, y - 0.9, z + 2.4), (hi, y + 0.9, z + 2.55), canopy_), "building")
    if lit:
        lx = x + facing * 0.2
        glow_box(
            mats,
            f"{name}_lantern",
            (lx - 0.08, y + 0.7, z + 1.9),
            (lx + 0.08, y + 0.86, z + 2.15),
            WINDOW_WARM,
            3000.0,
            "light_source",
        )
        point_lamp(f"{name}_light", (x + facing * 0.3, y + 0.78, z + 2.0), cd, WINDOW_WARM)


def build_close(mats: Materials) -> None:
    """A narrow residential street (a close) at night: a 5.6 m carriageway of wet asphalt
    (roughness 0.16, large puddles of 0.02 over two fifths; crowned 6 cm; flagged as road),
    cars parked along both kerbs leaving one lane between them, 1.6 m pavements, low brick
    garden walls with gate gaps, front gardens of lawn and hedges, pairs of two-storey
    rendered houses set 5.5 m back with a few lit windows and porches, most with a warm
    porch lantern (60-150 cd); a single LED 3800 K street lamp (1.6 kcd, 6 m) on the right
    pavement 34 m ahead; the street ends 96 m ahead at a T junction before a terrace; a car
    ahead pulling away with its tail lights (12 cd). A people carrier's camera 1.55 m up on
    the centre line (the only lane free)."""
    half = 2.8
    asphalt = mats.principled(
        "wet_asphalt", albedo="asphalt_close_g", roughness_map="puddles_close_g", road=True
    )
    line = straight(lambda s: 0.0)
    xs = [(float(x), crown(float(x), half, 0.06)) for x in np.linspace(-half, half, 9)]
    tag(ribbon("road", line, np.arange(-10.0, 104.01, 1.0), xs, asphalt, 2.0), "road")
    # the cross street at the end, a terrace facing the close
    tag(box("cross_street", (-40.0, 96.0, -0.3), (40.0, 103.0, 0.0), asphalt, 2.0), "road")
    flags = mats.principled("flags_g", albedo="flags_g", roughness=0.45)
    kerb, walk = 0.12, 1.6
    for k, sx in enumerate((-1.0, 1.0)):
        xa, xb = sorted((sx * half, sx * (half + walk)))
        tag(box(f"pavement{k}", (xa, -10.0, -0.3), (xb, 96.0, kerb), flags, 2.0), "sidewalk")
    tag(box("far_pavement", (-40.0, 103.0, -0.3), (40.0, 105.0, kerb), flags, 2.0), "sidewalk")
    brick = mats.principled("garden_wall_g", albedo="garden_wall_g", roughness=0.8)
    lawn_ = mats.principled("garden_g", albedo="hedge_g", roughness=0.9)
    hedge = mats.principled("hedge_g", albedo="hedge_g", roughness=0.95)
    render = mats.principled("houses_g", albedo="houses_g", roughness=0.85)
    roofs = mats.principled("roof_tiles_g", (0.08, 0.05, 0.045), roughness=0.6)
    rng = np.random.default_rng(181)
    back = half + walk + 5.5  # the houses' front walls
    for sx in (-1.0, 1.0):
        s, k = -10.0, 0
        while s < 88.0:
            width = float(rng.uniform(13.0, 16.0))  # a pair of semi-detached houses
            tag_ = f"{'l' if sx < 0 else 'r'}{k}"
            x_wall = sx * (half + walk)
            xa, xb = sorted((x_wall, x_wall + sx * 0.25))
            gates = (s + 2.0, s + width / 2.0 + 2.0)
            edges = [s, gates[0], gates[0] + 1.2, gates[1], gates[1] + 1.2, s + width]
            for j in range(0, len(edges), 2):
                tag(
                    box(
                        f"garden_wall_{tag_}_{j}",
                        (xa, edges[j], 0.0),
                        (xb, edges[j + 1], 0.9),
                        brick,
                        1.0,
                    ),
                    "wall",
                )
            ga, gb = sorted((x_wall + sx * 0.25, sx * back))
            tag(box(f"garden_{tag_}", (ga, s, -0.3), (gb, s + width, 0.1), lawn_, 2.0), "terrain")
            if rng.uniform() < 0.6:
                ha, hb = sorted((x_wall + sx * 0.3, x_wall + sx * 1.1))
                tag(
                    box(
                        f"hedge_{tag_}",
                        (ha, gates[0] + 1.4, 0.1),
                        (hb, gates[1] - 0.2, float(rng.uniform(1.2, 1.8))),
                        hedge,
                        1.0,
                    ),
                    "vegetation",
                )
            fa, fb = sorted((sx * back, sx * (back + 9.0)))
            top = float(rng.uniform(5.6, 6.4))
            tag(
                box(f"house_{tag_}", (fa, s + 0.5, 0.0), (fb, s + width - 0.5, top), render, 5.4),
                "building",
            )
            tag(
                box(
                    f"roof_{tag_}",
                    (fa - 0.3, s + 0.3, top),
                    (fb + 0.3, s + width - 0.3, top + 0.4),
                    roofs,
                ),
                "building",
            )
            for j, door_y in enumerate((s + 2.6, s + width - 2.6)):
                porch(
                    mats,
                    f"porch_{tag_}_{j}",
                    (sx * back, door_y, 0.1),
                    -sx,
                    rng.uniform() < 0.7,
                    float(rng.uniform(60.0, 150.0)),
                )
            for j in range(int(rng.integers(0, 3))):
                wy = float(rng.uniform(s + 4.0, s + width - 5.0))
                wz = 0.9 if rng.uniform() < 0.5 else 3.7
                lo, hi = sorted((sx * back - sx * 0.04, sx * back - sx * 0.01))
                glow_box(
                    mats,
                    f"window_{tag_}_{j}",
                    (lo, wy, wz),
                    (hi, wy + 1.2, wz + 1.2),
                    WINDOW_WARM,
                    float(rng.uniform(10.0, 25.0)),
                    "building",
                )
            s, k = s + width, k + 1
    tag(box("terrace", (-40.0, 110.0, 0.0), (40.0, 119.0, 8.0), render, 4.0), "building")
    for j, x in enumerate((-9.0, -3.5, 4.0, 11.0)):
        glow_box(
            mats,
            f"terrace_window{j}",
            (x, 109.96, 4.0),
            (x + 1.2, 109.99, 5.3),
            WINDOW_WARM,
            18.0,
            "building",
        )
    for k, (x, y) in enumerate(((-9.5, 20.0), (10.0, 58.0), (-10.5, 71.0))):
        tree(
            mats,
            f"tree{k}",
            (x, y, 0.1),
            float(rng.uniform(6.0, 9.0)),
            False,
            60 + k,
            leaves="hedge_g",
        )
    # the single street lamp
    metal = mats.principled("lamp_metal_g", (0.1, 0.1, 0.1), roughness=0.45, metallic=0.6)
    post_lamp(mats, "lamp", (half + 0.5, 34.0, kerb), 6.0, [(-1.1, 0.0)], LED_3800, 1600.0, metal)
    # parked cars along both kerbs, a car pulling away
    paints = [
        mats.principled(
            "paint_silver_g", (0.4, 0.41, 0.43), roughness=0.25, metallic=0.8, coat=1.0
        ),
        mats.principled("paint_black_g", (0.02, 0.02, 0.022), roughness=0.25, coat=1.0),
        mats.principled("paint_white_close_g", (0.6, 0.6, 0.58), roughness=0.3, coat=1.0),
        mats.principled("paint_green_g", (0.03, 0.1, 0.05), roughness=0.3, coat=1.0),
        mats.principled("paint_maroon_g", (0.15, 0.02, 0.03), roughness=0.3, coat=1.0),
    ]
    inst = 1
    for sx, ys in (
        (-1.0, (9.0, 15.5, 27.0, 40.0, 47.0, 62.0, 80.0)),
        (1.0, (12.0, 21.0, 44.0, 52.0, 67.0, 74.0)),
    ):
        for y in ys:
            y_ = y + float(rng.uniform(-0.6, 0.6))
            car(
                mats,
                f"parked{inst}",
                (sx * 1.85, y_, 0.0),
                0.0 if sx > 0 else math.pi,
                paints[inst % 5],
                inst,
            )
            inst += 1
    tw = car(mats, "car_ahead", (0.0, 36.0, 0.05), 0.0, paints[4], inst)
    tail_lights(mats, "taillight", tw, 0.0, inst, cd=12.0)
    eye = (0.0, 0.0, 0.06 + 1.55)
    camera("driver", eye, pitched(np.array([0.0, 1.0, 0.0]), 2.0), 42.0, 512, 384)


#: Eighth set: the bus station street's LED 2900 K lamps, its canopy's LED 4800 K luminaires
#: and the cool 6500 K of its adverts and billboard; the car park deck's LED 5200 K columns and
#: its stair tower's 3600 K light. Linear sRGB of the blackbody, peak 1.
LED_2900 = (1.0, 0.464, 0.135)
CANOPY_4800 = (1.0, 0.771, 0.579)
ADVERT_6500 = (1.0, 0.944, 0.992)
LED_5200 = (1.0, 0.819, 0.68)
STAIR_3600 = (1.0, 0.594, 0.283)


def car_paints(mats, suffix: str) -> list:
    """Car body paints with colour and gloss (a clear coat; the grey and silver metallic)."""
    return [
        mats.principled(f"paint_red_{suffix}", (0.35, 0.03, 0.03), roughness=0.3, coat=1.0),
        mats.principled(
            f"paint_silver_{suffix}", (0.55, 0.56, 0.58), roughness=0.3, metallic=0.8, coat=1.0
        ),
        mats.principled(f"paint_white_{suffix}", (0.7, 0.7, 0.68), roughness=0.3, coat=1.0),
        mats.principled(f"paint_blue_{suffix}", (0.04, 0.12, 0.35), roughness=0.3, coat=1.0),
        mats.principled(f"paint_yellow_{suffix}", (0.6, 0.42, 0.04), roughness=0.3, coat=1.0),
        mats.principled(
            f"paint_grey_{suffix}", (0.2, 0.21, 0.22), roughness=0.3, metallic=0.6, coat=1.0
        ),
        mats.principled(f"paint_green_{suffix}", (0.05, 0.2, 0.1), roughness=0.3, coat=1.0),
    ]


def build_bus_station(mats: Materials) -> None:
    """A town-centre street past a bus station at night: a level carriageway of wet asphalt
    (roughness 0.12, puddles 0.025 on 22 %; crowned 7 cm; flagged as road) with a 2.3 m
    parking lane on the left, and on the right a bus bay (3.3 m, 58 m long, the same asphalt)
    along the bus station's platform; over the platform a long canopy (62 x 6.4 m, underside
    4.2 m up) with two rows of LED 4800 K luminaires (1.5 kcd each, every 6 m), lit advert
    panels at the platform's edge (300 cd/m2, 6500 K) and a glazed concourse lit from inside
    (70 cd/m2) behind it; two buses standing in the bay with lit windows and tail lights. On
    the left, near the kerb, a shopping arcade's ground floor of tall lit shop windows (4.2 x
    3.2 m, 80-160 cd/m2, warm and cool) under offices, a cinema's marquee projecting over the
    pavement (its lit front 350 cd/m2, a row of bulbs under it) and a lit billboard (6 x 4 m,
    250 cd/m2) on the wall above; LED 2900 K lamps (2.6 kcd, 8 m) on both sides; cars parked
    in the parking lane, a car ahead with tail lights (12 cd), an oncoming car (LED headlights,
    13 kcd); a junction 104 m ahead before a terrace. A hatchback's camera 1.2 m up."""
    asphalt = mats.principled(
        "wet_asphalt", albedo="asphalt_h", roughness_map="puddles_h", road=True
    )
    left, right = -5.8, 3.5  # the kerbs (the parking lane x < -3.5)
    centre, half = (left + right) / 2.0, (right - left) / 2.0
    line = straight(lambda s: 0.0)
    xs = [(float(x), crown(float(x) - centre, half, 0.07)) for x in np.linspace(left, right, 11)]
    tag(ribbon("road", line, np.arange(-10.0, 104.01, 1.0), xs, asphalt, 2.0), "road")
    flat = lambda x, y: 0.0  # noqa: E731
    bay = grid(
        "bus_bay", np.linspace(right, 6.8, 4), np.linspace(6.0, 64.0, 30), flat, asphalt, 2.0
    )
    tag(bay, "road")
    tag(box("cross_street", (-60.0, 104.0, -0.3), (60.0, 114.0, 0.0), asphalt, 2.0), "road")
    paint = mats.principled("road_paint_h", (0.6, 0.6, 0.58), roughness=0.35, road=True)
    marks = []
    for y in np.arange(-8.0, 100.0, 6.0):  # the centre line, dashed
        marks.append(((centre - 0.06, y), (centre + 0.06, y + 3.0)))
    for y in np.arange(6.5, 63.0, 1.0):  # the bus bay's edge, short dashes
        marks.append(((right - 0.05, y), (right + 0.1, y + 0.5)))
    for k, ((xa, ya), (xb, yb)) in enumerate(marks):
        z = crown(min((xa + xb) / 2.0, right) - centre, half, 0.07)
        tag(box(f"mark{k}", (xa, ya, z - 0.02), (xb, yb, z + 0.004), paint), "marking")
    # pavements and the platform
    flags = mats.principled("platform_h", albedo="platform_h", roughness=0.4)
    kerb = 0.15
    for k, (lo, hi) in enumerate(
        (
            ((-9.5, -10.0), (left, 104.0)),
            ((right, -10.0), (12.5, 6.0)),
            ((6.8, 6.0), (12.5, 64.0)),
            ((right, 64.0), (12.5, 104.0)),
        )
    ):
        tag(box(f"pavement{k}", (*lo, -0.3), (*hi, kerb), flags, 2.0), "sidewalk")
    tag(box("far_pavement", (-60.0, 114.0, -0.3), (60.0, 117.0, kerb), flags, 2.0), "sidewalk")
    # the bus station: canopy, luminaires, adverts, concourse
    steel = mats.principled("canopy_h", (0.3, 0.31, 0.33), roughness=0.4, metallic=0.7)
    tag(box("canopy", (6.4, 4.0, 4.2), (12.8, 66.0, 4.6), steel), "building")
    for k, y in enumerate(np.arange(7.0, 64.0, 12.0)):
        tag(box(f"canopy_column{k}", (11.6, y - 0.15, kerb), (11.9, y + 0.15, 4.2), steel), "pole")
    for k, y in enumerate(np.arange(7.0, 64.0, 6.0)):
        for j, x in enumerate((8.0, 10.8)):
            lamp_head(mats, f"canopy_light{k}_{j}", (x, y, 4.05), (0.6, 1.2), CANOPY_4800, 1500.0)
    for k, y in enumerate(np.arange(10.0, 62.0, 10.0)):
        glow_box(
            mats,
            f"advert{k}",
            (7.0, y, kerb + 0.3),
            (7.25, y + 1.2, kerb + 2.1),
            ADVERT_6500,
            300.0,
            "traffic_sign",
        )
    glass = mats.principled("concourse_glass_h", (0.02, 0.022, 0.025), roughness=0.05, coat=1.0)
    tag(box("concourse_frame", (12.5, 4.0, 0.0), (24.0, 66.0, 4.2), glass, 4.0), "building")
    glow_box(mats, "concourse", (12.45, 5.0, 0.3), (12.5, 65.0, 3.9), CANOPY_4800, 45.0, "building")
    board = mats.principled("board_h", (0.01, 0.01, 0.012), roughness=0.3)
    tag(box("departures", (9.0, 30.0, 2.6), (9.1, 32.4, 3.5), board), "traffic_sign")
    glow_box(
        mats, "departures_text", (8.97, 30.2, 2.75), (9.0, 32.2, 3.35), AMBER, 120.0, "traffic_sign"
    )
    offices = mats.principled("offices_h", albedo="offices_h", roughness=0.7)
    tag(box("station_offices", (12.5, 66.0, 0.0), (24.0, 100.0, 12.0), offices, 9.0), "building")
    # two buses in the bay with lit windows and tail lights
    liveries = [
        mats.principled("bus_livery_h", (0.5, 0.05, 0.04), roughness=0.3, coat=1.0),
        mats.principled("bus_livery2_h", (0.05, 0.2, 0.45), roughness=0.3, coat=1.0),
    ]
    for k, y in enumerate((32.0, 52.0)):
        inst = 20 + k
        tw = bus(mats, f"bus{k}", (5.15, y, 0.0), 0.0, liveries[k], inst)
        glow_box(
            mats,
            f"bus_windows{k}",
            (3.88, y - 4.6, 1.35),
            (3.9, y + 4.8, 2.6),
            COOL_WHITE,
            35.0,
            "bus",
        )
        for j, x in enumerate((-0.9, 0.9)):
            car_light(
                mats, f"bus_tail{k}{j}", tw, 0.0, (x, -5.5, 0.9), -1.0, RED, 800.0, 12.0, 40.0, inst
            )
    # the shopping arcade on the left: shop windows, marquee, billboard, offices above
    front = -9.5
    tag(box("arcade", (front - 14.0, -10.0, 0.0), (front, 100.0, 16.0), offices, 9.0), "building")
    stone = mats.principled("arcade_stone_h", (0.18, 0.17, 0.16), roughness=0.6)
    tag(
        box("arcade_plinth", (front, -10.0, 0.0), (front + 0.3, 100.0, 4.2), stone, 2.0), "building"
    )
    rng = np.random.default_rng(201)
    k, y = 0, -8.0
    while y < 96.0:
        warm = rng.uniform() < 0.5
        glow_box(
            mats,
            f"shop_window{k}",
            (front + 0.3, y, 0.35),
            (front + 0.33, y + 4.2, 3.55),
            SHOP_WARM if warm else COOL_WHITE,
            float(rng.choice((50.0, 80.0, 110.0))),
            "building",
        )
        k, y = k + 1, y + 5.2
    tag(box("marquee", (front, 40.0, 4.0), (-6.3, 52.0, 5.4), stone), "building")
    glow_box(
        mats,
        "marquee_front",
        (-6.32, 40.2, 4.15),
        (-6.28, 51.8, 5.25),
        ADVERT_6500,
        350.0,
        "traffic_sign",
    )
    for j, (ya, yb) in enumerate(((39.96, 40.0), (52.0, 52.04))):
        glow_box(
            mats,
            f"marquee_end{j}",
            (front + 0.4, ya, 4.15),
            (-6.4, yb, 5.25),
            ADVERT_6500,
            350.0,
            "traffic_sign",
        )
    for j, y in enumerate(np.arange(41.0, 52.0, 2.0)):
        glow_box(
            mats,
            f"marquee_bulb{j}",
            (-6.6, y - 0.06, 3.9),
            (-6.48, y + 0.06, 4.0),
            WINDOW_WARM,
            3000.0,
            "light_source",
        )
        point_lamp(f"marquee_bulb{j}_light", (-6.54, y, 3.85), 150.0, WINDOW_WARM)
    glow_box(
        mats,
        "billboard",
        (front + 0.02, 58.0, 6.5),
        (front + 0.06, 64.0, 10.5),
        ADVERT_6500,
        250.0,
        "traffic_sign",
    )
    # the terrace beyond the junction
    tag(box("terrace", (-60.0, 118.0, 0.0), (60.0, 128.0, 11.0), offices, 9.0), "building")
    for j, x in enumerate((-14.0, -6.0, 3.0, 9.5, 17.0)):
        glow_box(
            mats,
            f"terrace_window{j}",
            (x, 117.96, 4.5),
            (x + 1.4, 117.99, 6.0),
            WINDOW_WARM,
            25.0,
            "building",
        )
    # street lamps
    metal = mats.principled("lamp_metal_h", (0.12, 0.12, 0.13), roughness=0.45, metallic=0.6)
    for k, (x, y, dx) in enumerate(
        (
            (-6.3, 14.0, 1.4),
            (-6.3, 34.0, 1.4),
            (-6.3, 78.0, 1.4),
            (4.0, 72.0, -1.2),
            (4.0, 98.0, -1.2),
        )
    ):
        post_lamp(mats, f"lamp{k}", (x, y, kerb), 8.0, [(dx, 0.0)], LED_2900, 2600.0, metal)
    # cars: parked in the parking lane, one ahead, one oncoming
    paints = car_paints(mats, "h")
    inst = 1
    for y in (4.0, 10.5, 24.0, 58.0, 66.0, 84.0):
        car(
            mats,
            f"parked{inst}",
            (-4.65, y + float(rng.uniform(-0.5, 0.5)), 0.0),
            0.0,
            paints[inst % 7],
            inst,
        )
        inst += 1
    tw = car(mats, "car_ahead", (1.75, 27.0, 0.02), 0.0, paints[2], inst)
    tail_lights(mats, "taillight", tw, 0.0, inst, cd=12.0)
    inst += 1
    tw = car(mats, "oncoming", (-1.75, 74.0, 0.02), math.pi, paints[5], inst)
    headlights(mats, "oncoming_head", tw, math.pi, inst, colour=LED_6000, cd=13000.0, pitch=1.0)
    eye = (1.75, 0.0, crown(1.75 - centre, half, 0.07) + 1.2)
    camera("driver", eye, pitched(np.array([0.0, 1.0, 0.0]), 1.5), 34.0, 736, 384)


def build_car_park_deck(mats: Materials) -> None:
    """The open top deck of a multi-storey car park at night, 15 m above the town: 42 x 84 m
    of wet concrete in 2.5 m panels with oil stains (roughness 0.18, puddles 0.03 on 30 %,
    falling gently to the edges; flagged as road, material `wet_deck`), three aisles between
    rows of painted bays (2.5 x 5 m), lamp columns (6 m, two LED 5200 K heads of 2 kcd each)
    every 16 m along the back-to-back bays, 1.1 m concrete parapets, a stair and lift tower
    with lit glazing (3600 K, 60 cd/m2), a green exit sign and a lit car park sign; beyond the
    parapets the town's taller blocks with lit windows; nine cars parked in the bays (painted,
    glossy), a car driving away to the exit with its tail lights (12 cd) and one coming down
    our aisle towards us (LED headlights, 12 kcd). A van's camera 1.7 m up in the middle
    aisle."""
    deck = mats.principled("wet_deck", albedo="deck_h", roughness_map="deck_wet_h", road=True)
    fall = lambda x, y: -0.12 * abs(x) / 21.0 - 0.002 * y  # noqa: E731
    tag(
        grid("deck", np.linspace(-21.0, 21.0, 22), np.linspace(-10.0, 78.0, 45), fall, deck, 10.0),
        "road",
    )
    paint = mats.principled("bay_paint_h", (0.65, 0.65, 0.6), roughness=0.35, road=True)
    marks = []
    for xa, xb in (
        (-19.0, -14.0),
        (-8.0, -3.0),
        (-13.0, -8.0),
        (3.0, 8.0),
        (8.0, 13.0),
        (14.0, 19.0),
    ):
        for y in np.arange(0.0, 62.6, 2.5):
            marks.append(((xa, y - 0.05), (xb, y + 0.05)))
    for x in (-8.0, 8.0):  # the line between back-to-back bays
        marks.append(((x - 0.05, 0.0), (x + 0.05, 62.5)))
    for k, ((xa, ya), (xb, yb)) in enumerate(marks):
        z = fall((xa + xb) / 2.0, (ya + yb) / 2.0)
        tag(box(f"mark{k}", (xa, ya, z - 0.02), (xb, yb, z + 0.004), paint), "marking")
    # parapets and the stair tower
    parapet = mats.principled("parapet_h", albedo="parapet_h", roughness=0.75)
    for k, (lo, hi) in enumerate(
        (
            ((-21.5, -10.0), (-21.0, 78.0)),
            ((21.0, -10.0), (21.5, 78.0)),
            ((-21.5, 78.0), (21.5, 78.5)),
        )
    ):
        tag(box(f"parapet{k}", (*lo, -0.3), (*hi, 1.1), parapet, 3.0), "wall")
    tag(box("stair_tower", (14.0, 68.0, -0.3), (21.0, 78.0, 7.5), parapet, 3.0), "building")
    glow_box(
        mats, "stair_glazing", (13.96, 70.0, 0.4), (14.0, 76.5, 6.8), STAIR_3600, 60.0, "building"
    )
    glow_box(
        mats,
        "exit_sign",
        (13.9, 68.5, 2.4),
        (13.95, 69.7, 2.8),
        SIGNAL_GREEN,
        150.0,
        "traffic_sign",
    )
    glow_box(
        mats,
        "car_park_sign",
        (13.9, 70.5, 6.9),
        (13.95, 72.5, 7.4),
        (0.05, 0.25, 1.0),
        120.0,
        "traffic_sign",
    )
    tag(box("ramp_wall", (-21.0, 64.0, -0.3), (-13.0, 64.3, 1.1), parapet, 3.0), "wall")
    # lamp columns
    metal = mats.principled("lamp_metal_h2", (0.35, 0.36, 0.37), roughness=0.45, metallic=0.7)
    k = 0
    for x in (-8.0, 8.0):
        for y in (5.0, 21.0, 37.0, 53.0):
            post_lamp(
                mats,
                f"column{k}",
                (x, y, fall(x, y)),
                6.0,
                [(-0.7, 0.0), (0.7, 0.0)],
                LED_5200,
                2000.0,
                metal,
            )
            k += 1
    # the town beyond: blocks with lit windows
    town = mats.principled("town_h", albedo="skyline_h", roughness=0.8)
    rng = np.random.default_rng(211)
    blocks = (
        (-90.0, 120.0, 30.0, 30.0),
        (-20.0, 170.0, 40.0, 40.0),
        (40.0, 140.0, 25.0, 24.0),
        (110.0, 90.0, 30.0, 36.0),
        (-120.0, 40.0, 25.0, 22.0),
        (90.0, 10.0, 20.0, 28.0),
        (10.0, 260.0, 60.0, 52.0),
        (-60.0, 230.0, 30.0, 45.0),
    )
    for k, (x, y, w, top) in enumerate(blocks):
        tag(
            box(
                f"block{k}",
                (x - w / 2, y - w / 2, -15.0),
                (x + w / 2, y + w / 2, top - 15.0),
                town,
                12.0,
            ),
            "building",
        )
        face = y - w / 2 - 0.03  # the face towards the deck
        for j in range(int(rng.integers(6, 12))):
            wx = float(rng.uniform(x - w / 2 + 1.0, x + w / 2 - 3.0))
            wz = float(rng.uniform(-12.0, top - 17.0))
            glow_box(
                mats,
                f"block_window{k}_{j}",
                (wx, face, wz),
                (wx + 1.6, face + 0.02, wz + 1.3),
                WINDOW_WARM if rng.uniform() < 0.6 else COOL_WHITE,
                float(rng.uniform(15.0, 40.0)),
                "building",
            )
    # parked cars (nose in, across the bays), a car leaving, a car coming down our aisle
    paints = car_paints(mats, "deck")
    inst = 1
    for x, y in (
        (-5.5, 3.75),
        (-5.5, 13.75),
        (-5.5, 16.25),
        (-5.5, 36.25),
        (5.5, 8.75),
        (5.5, 26.25),
        (5.5, 28.75),
        (10.5, 21.25),
        (-10.5, 43.75),
    ):
        heading = math.pi / 2.0 if x < 0 else -math.pi / 2.0
        if abs(x) > 8.0:
            heading = -heading
        car(mats, f"parked{inst}", (x, y, fall(x, y)), heading, paints[inst % 7], inst)
        inst += 1
    tw = car(mats, "leaving", (1.4, 33.0, fall(1.4, 33.0)), 0.0, paints[3], inst)
    tail_lights(mats, "taillight", tw, 0.0, inst, cd=12.0)
    inst += 1
    tw = car(mats, "coming", (-1.5, 50.0, fall(1.5, 50.0)), math.pi, paints[1], inst)
    headlights(mats, "coming_head", tw, math.pi, inst, colour=LED_6000, cd=12000.0, pitch=1.5)
    eye = (0.9, 0.0, fall(0.9, 0.0) + 1.7)
    camera("driver", eye, pitched(np.array([0.0, 1.0, 0.0]), 2.0), 42.0, 624, 416)


LED_3200 = (1.0, 0.52, 0.19)
GOLD_2500 = (1.0, 0.36, 0.065)
SHOWROOM_5500 = (1.0, 0.84, 0.72)
LED_4400 = (1.0, 0.75, 0.52)
SIGN_GOLD = (1.0, 0.6, 0.12)
SOS_BLUE = (0.05, 0.3, 1.0)


def build_hotel_front(mats: Materials) -> None:
    """A boulevard past a grand hotel at night: a level carriageway of wet asphalt (8.4 m,
    two lanes and cycle strips; roughness 0.13, puddles 0.022 on a quarter; crowned 6 cm;
    flagged as road). On the right the hotel's drive (6.5 x 32 m of wet granite setts,
    flagged as road, material `hotel_drive`) under a porte-cochere (9 x 16 m, underside 4.6 m
    up) whose soffit glows (70 cd/m2, 2500 K) with twelve gold downlights (1.2 kcd each) and
    whose fascia along the road and ends are lit (400 cd/m2); the lobby's tall glazing lit
    from inside (60 cd/m2) behind it, a restaurant's lit windows, a lit blade sign and a name
    sign on the tower, a few lit rooms; two taxis in the drive. On the left, 4.5 m from the
    kerb, a car showroom's open glass front (42 x 6 m, mullions every 3 m) into a hall 9 m
    deep lit by ceiling strips (500 cd/m2, 5500 K) and a glowing back wall (45 cd/m2) over a
    glossy floor with five display cars, under a lit blue brand band (200 cd/m2). LED 3200 K
    lamps (2.4 kcd, 9 m) on both sides; a car ahead with tail lights (12 cd), an oncoming car
    (halogen headlights, 14 kcd), a car parked by the showroom; a junction 110 m ahead before
    a terrace. A low saloon's camera 1.1 m up."""
    asphalt = mats.principled(
        "wet_asphalt", albedo="asphalt_i", roughness_map="puddles_i", road=True
    )
    left, right = -4.2, 4.2
    half = right
    line = straight(lambda s: 0.0)
    xs = [(float(x), crown(float(x), half, 0.06)) for x in np.linspace(left, right, 11)]
    tag(ribbon("road", line, np.arange(-10.0, 110.01, 1.0), xs, asphalt, 2.0), "road")
    tag(box("cross_street", (-70.0, 110.0, -0.3), (70.0, 120.0, 0.0), asphalt, 2.0), "road")
    paint = mats.principled("road_paint_i", (0.62, 0.62, 0.6), roughness=0.35, road=True)
    marks = []
    for y in np.arange(-8.0, 106.0, 9.0):  # the centre line, long dashes
        marks.append(((-0.07, y), (0.07, y + 4.5)))
    for x in (-3.0, 3.0):  # the cycle strips' lines, solid
        marks.append(((x - 0.06, -10.0), (x + 0.06, 108.0)))
    for k, ((xa, ya), (xb, yb)) in enumerate(marks):
        z = crown((xa + xb) / 2.0, half, 0.06)
        tag(box(f"mark{k}", (xa, ya, z - 0.02), (xb, yb, z + 0.004), paint), "marking")
    # the hotel's drive under the porte-cochere, flush with the road
    drive = mats.principled("hotel_drive", albedo="drive_i", roughness_map="drive_wet_i", road=True)
    flat = lambda x, y: 0.0  # noqa: E731
    tag(
        grid("drive", np.linspace(right, 10.7, 5), np.linspace(10.0, 42.0, 17), flat, drive, 1.5),
        "road",
    )
    flags = mats.principled("flags_i", albedo="flags_i", roughness=0.35)
    kerb = 0.14
    for k, (lo, hi) in enumerate(
        (
            ((-8.7, -10.0), (left, 110.0)),
            ((right, -10.0), (14.0, 10.0)),
            ((10.7, 10.0), (14.0, 42.0)),
            ((right, 42.0), (14.0, 110.0)),
        )
    ):
        tag(box(f"pavement{k}", (*lo, -0.3), (*hi, kerb), flags, 2.0), "sidewalk")
    tag(box("far_pavement", (-70.0, 120.0, -0.3), (70.0, 123.0, kerb), flags, 2.0), "sidewalk")
    # the porte-cochere: slab, columns, glowing soffit, downlights, lit fascia
    stone = mats.principled("hotel_stone_i", (0.42, 0.38, 0.32), roughness=0.5)
    tag(box("porte_cochere", (4.6, 18.0, 4.6), (13.6, 34.0, 5.5), stone), "building")
    for k, (x, y) in enumerate(((5.0, 18.6), (5.0, 33.4), (13.2, 18.6), (13.2, 33.4))):
        tag(
            box(f"pc_column{k}", (x - 0.25, y - 0.25, 0.0), (x + 0.25, y + 0.25, 4.6), stone),
            "pole",
        )
    glow_box(mats, "pc_soffit", (5.2, 18.6, 4.56), (13.0, 33.4, 4.6), GOLD_2500, 70.0, "building")
    k = 0
    for x in (6.6, 9.1, 11.6):
        for y in (20.5, 24.2, 27.8, 31.5):
            lamp_head(mats, f"pc_light{k}", (x, y, 4.4), (0.5, 0.5), GOLD_2500, 1200.0)
            k += 1
    glow_box(
        mats, "pc_fascia", (4.55, 18.0, 4.75), (4.6, 34.0, 5.35), SIGN_GOLD, 400.0, "traffic_sign"
    )
    for j, (ya, yb) in enumerate(((17.95, 18.0), (34.0, 34.05))):
        glow_box(
            mats,
            f"pc_fascia_end{j}",
            (4.6, ya, 4.75),
            (13.6, yb, 5.35),
            SIGN_GOLD,
            400.0,
            "traffic_sign",
        )
    # the hotel: tower, lobby glazing, restaurant, signs, lit rooms
    hotel = mats.principled("hotel_i", albedo="hotel_i", roughness=0.6)
    tag(box("hotel", (14.0, 2.0, 0.0), (36.0, 64.0, 42.0), hotel, 8.0), "building")
    glow_box(mats, "lobby", (13.95, 17.0, 0.2), (14.0, 35.0, 6.5), WINDOW_WARM, 60.0, "building")
    for j, y in enumerate(np.arange(43.0, 61.0, 4.5)):
        glow_box(
            mats,
            f"restaurant{j}",
            (13.95, y, 0.6),
            (14.0, y + 3.6, 3.6),
            SHOP_WARM,
            60.0,
            "building",
        )
    glow_box(
        mats, "blade_sign", (13.2, 14.6, 6.5), (13.95, 15.0, 15.5), SIGN_GOLD, 250.0, "traffic_sign"
    )
    glow_box(
        mats, "name_sign", (13.9, 20.0, 36.0), (13.95, 32.0, 39.0), SIGN_GOLD, 300.0, "traffic_sign"
    )
    rng = np.random.default_rng(241)
    for j in range(28):
        y = float(rng.uniform(3.0, 61.0))
        z = float(2.67 * int(rng.integers(3, 14)) + 0.3)
        glow_box(
            mats,
            f"room{j}",
            (13.96, y, z),
            (13.99, y + 1.4, z + 1.5),
            WINDOW_WARM if rng.uniform() < 0.7 else COOL_WHITE,
            float(rng.uniform(12.0, 35.0)),
            "building",
        )
    # the car showroom on the left: glass front, mullions, brand band, panels above
    front = -8.7
    panels = mats.principled("showroom_i", albedo="showroom_i", roughness=0.45)
    deep = front - 9.0  # the showroom's back wall
    for j, (lo, hi) in enumerate(
        (
            ((front - 30.0, 4.0, 6.4), (front, 48.0, 9.0)),
            ((front - 30.0, 4.0, 0.0), (deep, 48.0, 6.4)),
            ((deep, 4.0, 0.0), (front, 5.0, 6.4)),
            ((deep, 47.0, 0.0), (front, 48.0, 6.4)),
        )
    ):
        tag(box(f"showroom{j}", lo, hi, panels, 6.0), "building")
    tiles = mats.principled("showroom_floor_i", (0.55, 0.55, 0.56), roughness=0.12, coat=0.5)
    tag(box("showroom_floor", (deep, 5.0, -0.3), (front, 47.0, 0.1), tiles, 1.0), "building")
    glow_box(
        mats,
        "showroom_back",
        (deep, 5.0, 0.1),
        (deep + 0.04, 47.0, 6.4),
        SHOWROOM_5500,
        45.0,
        "building",
    )
    for j, x in enumerate(np.arange(deep + 1.0, front, 2.0)):
        glow_box(
            mats,
            f"showroom_ceiling{j}",
            (x - 0.2, 5.5, 6.34),
            (x + 0.2, 46.5, 6.4),
            SHOWROOM_5500,
            500.0,
            "building",
        )
    display = car_paints(mats, "show")
    for j, (x, y) in enumerate(
        (
            (front - 3.0, 9.0),
            (front - 6.2, 17.0),
            (front - 3.0, 25.0),
            (front - 6.2, 33.0),
            (front - 3.0, 41.0),
        )
    ):
        car(mats, f"display{j}", (x, y, 0.1), 0.6 if j % 2 else -0.6, display[j + 1], 30 + j)
    frame = mats.principled("mullion_i", (0.05, 0.05, 0.055), roughness=0.3, metallic=0.8)
    for j, y in enumerate(np.arange(5.0, 47.1, 3.0)):
        tag(
            box(f"mullion{j}", (front + 0.04, y - 0.06, 0.2), (front + 0.14, y + 0.06, 6.2), frame),
            "building",
        )
    glow_box(
        mats,
        "brand_band",
        (front + 0.02, 8.0, 6.6),
        (front + 0.08, 44.0, 7.6),
        SOS_BLUE,
        200.0,
        "traffic_sign",
    )
    offices = mats.principled("offices_i", albedo="hotel_i", roughness=0.7)
    tag(
        box("left_block", (front - 20.0, 48.0, 0.0), (front, 108.0, 18.0), offices, 8.0), "building"
    )
    tag(
        box("left_block0", (front - 20.0, -12.0, 0.0), (front, 4.0, 14.0), offices, 8.0), "building"
    )
    tag(box("right_block", (14.0, 64.0, 0.0), (30.0, 108.0, 20.0), offices, 8.0), "building")
    for j in range(10):
        side = -1 if j % 2 else 1
        y = float(rng.uniform(52.0, 104.0))
        z = float(3.0 * int(rng.integers(1, 5)) + 0.5)
        x = front + 0.02 if side < 0 else 13.97
        glow_box(
            mats,
            f"block_window{j}",
            (x - 0.01, y, z),
            (x + 0.02, y + 1.3, z + 1.4),
            WINDOW_WARM,
            float(rng.uniform(15.0, 30.0)),
            "building",
        )
    tag(box("terrace", (-70.0, 123.0, 0.0), (70.0, 133.0, 12.0), offices, 8.0), "building")
    for j, x in enumerate((-20.0, -9.0, 2.0, 11.0, 23.0)):
        glow_box(
            mats,
            f"terrace_window{j}",
            (x, 122.96, 4.0),
            (x + 1.5, 122.99, 5.5),
            WINDOW_WARM,
            25.0,
            "building",
        )
    # street lamps (none in the drive's mouth)
    metal = mats.principled("lamp_metal_i", (0.1, 0.1, 0.11), roughness=0.45, metallic=0.6)
    for k, (x, y, dx) in enumerate(
        (
            (-5.0, 12.0, 1.5),
            (-5.0, 40.0, 1.5),
            (-5.0, 68.0, 1.5),
            (-5.0, 96.0, 1.5),
            (5.0, 4.0, -1.5),
            (5.0, 52.0, -1.5),
            (5.0, 80.0, -1.5),
        )
    ):
        post_lamp(mats, f"lamp{k}", (x, y, kerb), 9.0, [(dx, 0.0)], LED_3200, 2400.0, metal)
    # cars: two taxis in the drive, a car ahead, an oncoming car, one parked on the left
    paints = car_paints(mats, "i")
    taxi = mats.principled("paint_taxi_i", (0.02, 0.02, 0.022), roughness=0.25, coat=1.0)
    tw = car(mats, "taxi0", (7.3, 24.0, 0.0), 0.0, taxi, 1)
    tail_lights(mats, "taxi0_tail", tw, 0.0, 1, cd=10.0)
    car(mats, "taxi1", (7.3, 31.0, 0.0), 0.0, paints[4], 2)
    tw = car(mats, "car_ahead", (1.9, 30.0, 0.02), 0.0, paints[1], 3)
    tail_lights(mats, "taillight", tw, 0.0, 3, cd=12.0)
    tw = car(mats, "oncoming", (-1.9, 70.0, 0.02), math.pi, paints[3], 4)
    headlights(mats, "oncoming_head", tw, math.pi, 4, colour=HALOGEN, cd=14000.0, pitch=1.0)
    car(mats, "parked5", (-3.3, 56.0, 0.0), 0.0, paints[6], 5)
    eye = (1.9, 0.0, crown(1.9, half, 0.06) + 1.1)
    camera("driver", eye, pitched(np.array([0.0, 1.0, 0.0]), 1.5), 36.0, 752, 400)


def build_tunnel_portal(mats: Materials) -> None:
    """A mountain road at night running into a tunnel: a two-lane road (7.5 m) of wet asphalt
    (roughness 0.12, puddles 0.03 on a sixth; flagged as road) climbing at 1.2 % through a
    cutting between retaining walls that rise from 1 m to 9 m, with guardrails, edge lines and
    delineator posts, into a rectangular portal 70 m ahead in a concrete headwall under a
    wooded hillside; inside, the tunnel (10 m wide, 6.3 m high, walkways on both sides) bends
    left (R 320 m) from 110 m, its lower walls lined with light panels and its vault dark, two
    rows of LED 4400 K luminaires (2.2 kcd every 4 m in the entrance zone, 1.0 kcd every 10 m
    beyond), the road wet for 25 m inside and damp beyond (roughness 0.32, flagged as road,
    material `tunnel_asphalt`); lane signals and a lit name sign over the portal, blue SOS
    niches inside; LED 4400 K lamps (2 kcd, 10 m) on the approach; a car entering the tunnel
    with its tail lights (12 cd), an oncoming car coming out (xenon headlights, 14 kcd). A
    lorry's camera 2.1 m up."""
    grade = lambda s: 0.012 * s  # noqa: E731
    line = CentreLine(radius=320.0, bend_start=110.0, profile=grade)
    asphalt = mats.principled(
        "wet_asphalt", albedo="asphalt_pass_i", roughness_map="puddles_pass_i", road=True
    )
    inner = mats.principled(
        "tunnel_asphalt", albedo="asphalt_pass_i", roughness_map="tunnel_damp_i", road=True
    )
    half = 3.75
    xs = [(float(x), crown(float(x), half + 0.25, 0.05)) for x in np.linspace(-4.0, 4.0, 9)]
    tag(ribbon("road", line, np.arange(-10.0, 95.01, 1.0), xs, asphalt, 2.0), "road")
    tag(ribbon("tunnel_road", line, np.arange(95.0, 340.01, 2.0), xs, inner, 2.0), "road")
    paint = mats.principled("road_paint_i2", (0.62, 0.62, 0.6), roughness=0.35, road=True)
    k = 0
    for s in np.arange(-8.0, 330.0, 12.0):  # the centre line, dashed
        for x, length in ((0.0, 5.0), (-3.55, 12.0), (3.55, 12.0)):
            c, r = line.point(s), line.right(s)
            p = c + x * r
            obj = box(f"mark{k}", (-0.07, 0.0, -0.02), (0.07, length, 0.054), paint)
            obj.location = tuple(p)
            obj.rotation_euler = (math.atan(0.012), 0.0, line.heading(s))
            tag(obj, "marking")
            k += 1
    # the approach: verges, guardrails, retaining walls, hillsides
    portal = 70.0
    concrete = mats.principled("portal_i", albedo="portal_i", roughness=0.8)
    grass = mats.principled("slope_i", albedo="slope_i", roughness=0.85)
    for side in (-1.0, 1.0):
        tag(
            ribbon(
                f"verge{int(side)}",
                line,
                np.arange(-10.0, portal + 0.01, 2.0),
                [(4.0, 0.0), (7.0, 0.05)] if side > 0 else [(-7.0, 0.05), (-4.0, 0.0)],
                grass,
                2.0,
            ),
            "terrain",
        )

    def wall_top(y: float) -> float:
        """The cutting's depth: nothing at 10 m, 9 m at the portal."""
        return 9.0 * smoothstep((y - 10.0) / 60.0)

    tag(
        wall(
            "cut_wall_l",
            np.arange(10.0, portal + 0.01, 2.0),
            -7.0,
            grade,
            lambda y: grade(y) + wall_top(y),
            concrete,
            3.0,
            1.0,
        ),
        "wall",
    )
    tag(
        wall(
            "cut_wall_r",
            np.arange(10.0, portal + 0.01, 2.0),
            7.0,
            grade,
            lambda y: grade(y) + wall_top(y),
            concrete,
            3.0,
            -1.0,
        ),
        "wall",
    )

    def hill(x: float, y: float) -> float:
        """The hillsides beside the cutting, from the walls' tops up and away."""
        away = max(0.0, abs(x) - 7.0)
        bumps = 0.6 * math.sin(0.21 * x + 0.13 * y) * smoothstep(away / 5.0)
        return grade(max(min(y, portal), -10.0)) + wall_top(y) + 0.55 * away + bumps

    for side in (-1.0, 1.0):
        xs_h = np.linspace(7.0, 60.0, 16) * side
        tag(
            grid(
                f"hillside{int(side)}",
                sorted(xs_h),
                np.linspace(-10.0, portal + 2.0, 20),
                hill,
                grass,
                4.0,
            ),
            "terrain",
        )

    def above(x: float, y: float) -> float:
        """The hill over the tunnel, rising from the headwall's top."""
        return grade(portal) + 12.0 + 0.35 * (y - portal) + 0.2 * abs(x) + 0.8 * math.sin(0.17 * x)

    tag(
        grid(
            "hill_above",
            np.linspace(-80.0, 80.0, 24),
            np.linspace(portal + 1.0, 260.0, 24),
            above,
            grass,
            4.0,
        ),
        "terrain",
    )
    rail = mats.principled("guardrail_i", (0.5, 0.52, 0.55), roughness=0.35, metallic=0.8)
    for side in (-1.0, 1.0):
        x = 4.6 * side
        tag(
            box(f"guardrail{int(side)}", (x - 0.03, -10.0, 0.5), (x + 0.03, 12.0, 0.8), rail),
            "fence",
        )
        for j, y in enumerate(np.arange(-8.0, 12.0, 4.0)):
            tag(
                box(
                    f"rail_post{int(side)}_{j}",
                    (x - 0.06 + 0.1 * side, y - 0.06, 0.0),
                    (x + 0.06 + 0.1 * side, y + 0.06, 0.75),
                    rail,
                ),
                "pole",
            )
    white = mats.principled("delineator_i", (0.75, 0.75, 0.72), roughness=0.4)
    amber = mats.principled("reflector_i", (0.9, 0.45, 0.05), roughness=0.1, coat=1.0)
    for j, y in enumerate(np.arange(-5.0, 60.0, 16.0)):
        for side in (-1.0, 1.0):
            x = 5.2 * side
            z = grade(y)
            tag(
                box(
                    f"delineator{j}_{int(side)}",
                    (x - 0.06, y - 0.06, z),
                    (x + 0.06, y + 0.06, z + 1.0),
                    white,
                ),
                "pole",
            )
            tag(
                box(
                    f"reflector{j}_{int(side)}",
                    (x - 0.065, y - 0.065, z + 0.75),
                    (x + 0.065, y - 0.05, z + 0.93),
                    amber,
                ),
                "pole",
            )
    rng = np.random.default_rng(251)
    t = 0
    for side in (-1.0, 1.0):
        for y in np.arange(-6.0, 66.0, 9.0):
            x = side * float(rng.uniform(9.5, 30.0))
            tree(
                mats,
                f"tree{t}",
                (x, y, hill(x, y) - 0.2),
                float(rng.uniform(7.0, 12.0)),
                True,
                40 + t,
                leaves="slope_i",
            )
            t += 1
    for _ in range(10):
        x = float(rng.uniform(-40.0, 40.0))
        y = float(rng.uniform(portal + 8.0, 110.0))
        tree(
            mats,
            f"tree{t}",
            (x, y, above(x, y) - 0.2),
            float(rng.uniform(8.0, 13.0)),
            True,
            40 + t,
            leaves="slope_i",
        )
        t += 1
    # the portal: a headwall with a rectangular opening, lane signals and a name sign
    zp = grade(portal)
    tag(
        box(
            "headwall_l", (-40.0, portal, zp - 1.0), (-5.0, portal + 2.0, zp + 20.0), concrete, 3.0
        ),
        "wall",
    )
    tag(
        box("headwall_r", (5.0, portal, zp - 1.0), (40.0, portal + 2.0, zp + 20.0), concrete, 3.0),
        "wall",
    )
    tag(
        box(
            "headwall_top", (-5.0, portal, zp + 6.3), (5.0, portal + 2.0, zp + 20.0), concrete, 3.0
        ),
        "wall",
    )
    housing = mats.principled("signal_housing_i", (0.02, 0.02, 0.022), roughness=0.4)
    for j, x in enumerate((-1.9, 1.9)):
        tag(
            box(
                f"lane_signal{j}",
                (x - 0.45, portal - 0.25, zp + 6.6),
                (x + 0.45, portal, zp + 7.5),
                housing,
            ),
            "traffic_light",
        )
        colour = SIGNAL_GREEN if x > 0 else RED
        glow_box(
            mats,
            f"lane_signal_lamp{j}",
            (x - 0.3, portal - 0.28, zp + 6.75),
            (x + 0.3, portal - 0.25, zp + 7.35),
            colour,
            300.0,
            "traffic_light",
        )
    tag(
        box("name_board", (-3.2, portal - 0.2, zp + 8.0), (3.2, portal, zp + 9.0), housing),
        "traffic_sign",
    )
    glow_box(
        mats,
        "name_sign",
        (-3.0, portal - 0.23, zp + 8.15),
        (3.0, portal - 0.2, zp + 8.85),
        COOL_WHITE,
        60.0,
        "traffic_sign",
    )
    # the tunnel: walkways, light lined lower walls, a dark vault, luminaires, SOS niches
    lining = mats.principled("lining_i", albedo="lining_i", roughness=0.3, coat=0.5)
    vault = mats.principled("vault_i", (0.05, 0.05, 0.055), roughness=0.8)
    ss = np.arange(portal, 340.01, 2.0)
    walk = mats.principled("walkway_i", (0.2, 0.2, 0.19), roughness=0.7)
    tag(
        ribbon("walkway_r", line, ss, [(4.0, 0.0), (4.0, 0.25), (5.0, 0.25)], walk, 1.0), "sidewalk"
    )
    tag(
        ribbon("walkway_l", line, ss, [(-5.0, 0.25), (-4.0, 0.25), (-4.0, 0.0)], walk, 1.0),
        "sidewalk",
    )
    tag(
        ribbon("lining_r", line, ss, [(5.0, 0.25), (5.0, 4.5)], lining, 2.0, along_first=True),
        "wall",
    )
    tag(
        ribbon("lining_l", line, ss, [(-5.0, 4.5), (-5.0, 0.25)], lining, 2.0, along_first=True),
        "wall",
    )
    tag(
        ribbon("vault", line, ss, [(5.0, 4.5), (5.0, 6.3), (-5.0, 6.3), (-5.0, 4.5)], vault, 2.0),
        "wall",
    )
    tag(box("tunnel_end", (-60.0, 345.0, -5.0), (60.0, 346.0, 20.0), vault), "wall")
    k = 0
    for s in list(np.arange(portal + 2.0, portal + 42.0, 4.0)) + list(
        np.arange(portal + 48.0, 335.0, 10.0)
    ):
        cd = 2200.0 if s < portal + 42.0 else 1000.0
        for x in (-2.6, 2.6):
            p = line.point(s) + x * line.right(s)
            lamp_head(
                mats,
                f"tunnel_light{k}",
                (float(p[0]), float(p[1]), float(p[2]) + 6.05),
                (0.35, 1.2),
                LED_4400,
                cd,
            )
            k += 1
    for j, s in enumerate(np.arange(portal + 60.0, 330.0, 90.0)):
        p = line.point(s) + 4.97 * line.right(s)
        glow_box(
            mats,
            f"sos{j}",
            (float(p[0]) - 0.03, float(p[1]) - 0.6, float(p[2]) + 2.2),
            (float(p[0]), float(p[1]) + 0.6, float(p[2]) + 2.8),
            SOS_BLUE,
            150.0,
            "traffic_sign",
        )
    # approach lamps
    metal = mats.principled("lamp_metal_i2", (0.3, 0.31, 0.32), roughness=0.45, metallic=0.7)
    for j, (x, y, dx) in enumerate(((5.6, 18.0, -1.8), (-5.6, 40.0, 1.8), (5.6, 60.0, -1.8))):
        post_lamp(mats, f"lamp{j}", (x, y, grade(y)), 10.0, [(dx, 0.0)], LED_4400, 2000.0, metal)
    # cars: one entering the tunnel, one coming out of it
    paints = car_paints(mats, "i2")
    pitch = math.atan(0.012)
    tw = sloped_car(mats, "car_ahead", (1.9, 58.0, grade(58.0) + 0.03), 0.0, pitch, paints[0], 1)
    tail_lights(mats, "taillight", tw, 0.0, 1, cd=12.0)
    tw = sloped_car(
        mats, "oncoming", (-1.9, 92.0, grade(92.0) + 0.03), math.pi, -pitch, paints[2], 2
    )
    headlights(mats, "oncoming_head", tw, math.pi, 2, colour=XENON, cd=14000.0, pitch=1.0)
    eye = (1.9, 24.0, grade(24.0) + crown(1.9, half + 0.25, 0.05) + 2.1)
    camera("driver", eye, pitched(np.array([0.0, 1.0, 0.0]), 0.5), 34.0, 672, 384)


SCENES = {
    "hill_bend": build_hill_bend,
    "crossing": build_crossing,
    "tabletop": build_tabletop,
    # the second set (made after the first had been looked at)
    "roundabout": build_roundabout,
    "avenue": build_avenue,
    "shelf": build_shelf,
    # the third set (made after the first two had been looked at)
    "underpass": build_underpass,
    "hillside": build_hillside,
    "daylight_street": build_daylight_street,
    # the fourth set (made after the first three had been looked at)
    "bridge": build_bridge,
    "square": build_square,
    # the fifth set (made after the first four had been looked at)
    "quay": build_quay,
    "arterial": build_arterial,
    # the sixth set (made after the first five had been looked at)
    "tramway": build_tramway,
    "forecourt": build_forecourt,
    # the seventh set (made after the first six had been looked at)
    "toll_plaza": build_toll_plaza,
    "close": build_close,
    # the eighth set (made after the first seven had been looked at)
    "bus_station": build_bus_station,
    "car_park_deck": build_car_park_deck,
    # the ninth set (made after the first eight had been looked at)
    "hotel_front": build_hotel_front,
    "tunnel_portal": build_tunnel_portal,
}
#: The scene sets: `--set a` (the default) builds the first, `--set b` the second, `--set c`
#: the third, `--set d` the fourth, `--set e` the fifth, `--set f` the sixth, `--set g` the
#: seventh, `--set h` the eighth, `--set i` the ninth.
SETS = {
    "a": ("hill_bend", "crossing", "tabletop"),
    "b": ("roundabout", "avenue", "shelf"),
    "c": ("underpass", "hillside", "daylight_street"),
    "d": ("bridge", "square"),
    "e": ("quay", "arterial"),
    "f": ("tramway", "forecourt"),
    "g": ("toll_plaza", "close"),
    "h": ("bus_station", "car_park_deck"),
    "i": ("hotel_front", "tunnel_portal"),
}
#: The scenes with a wet road (the others have none).
STREETS = (
    "hill_bend",
    "crossing",
    "roundabout",
    "avenue",
    "underpass",
    "hillside",
    "bridge",
    "square",
    "quay",
    "arterial",
    "tramway",
    "forecourt",
    "toll_plaza",
    "close",
    "bus_station",
    "car_park_deck",
    "hotel_front",
    "tunnel_portal",
)
#: The streets with a dry road (no streaks; their road material is `dry_asphalt`).
DRY_STREETS = ("daylight_street",)
#: The streets whose road material the export checks is not `wet_asphalt` (the quay has no
#: asphalt: its cobbles are its road; the forecourt's concrete is flagged as well as the
#: asphalt of the road beyond it).
ROAD_MATERIAL = {
    "daylight_street": "dry_asphalt",
    "quay": "wet_cobbles",
    "forecourt": "wet_concrete",
    "car_park_deck": "wet_deck",
}


def export(out: Path, name: str) -> Path:
    """Saves the .blend and exports the .glb with Blender's exporter (defaults, plus cameras,
    punctual lights and custom properties as extras); checks the road's extras."""
    bpy.ops.wm.save_as_mainfile(filepath=str(out / f"{name}.blend"))
    glb = out / f"{name}.glb"
    bpy.ops.export_scene.gltf(
        filepath=str(glb),
        export_format="GLB",
        export_cameras=True,
        export_lights=True,
        export_extras=True,
    )
    doc, _ = read_glb(glb.read_bytes())
    roads = [
        m["name"]
        for m in doc.get("materials", [])
        if m.get("extras", {}).get("streaks", {}).get("road") is True
    ]
    road_name = ROAD_MATERIAL.get(name, "wet_asphalt")
    has_road = name in STREETS or name in DRY_STREETS
    if has_road and road_name not in roads:
        raise SystemExit(f"{glb}: the road material has no extras.streaks.road = true")
    if has_road:
        road = next(m for m in doc["materials"] if m["name"] == road_name)
        pbr = road.get("pbrMetallicRoughness", {})
        if "baseColorTexture" not in pbr or "metallicRoughnessTexture" not in pbr:
            raise SystemExit(f"{glb}: the road's textures were not exported")
    lights = doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    print(
        json.dumps(
            {
                "scene": name,
                "bytes": glb.stat().st_size,
                "road_materials": roads,
                "lights": len(lights),
                "cameras": len(doc.get("cameras", [])),
            }
        )
    )
    return glb


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--scenes", nargs="+", choices=list(SCENES))
    parser.add_argument("--set", choices=list(SETS), default="a", help="the scene set (a: first)")
    args = parser.parse_args()
    if args.scenes is None:
        args.scenes = list(SETS[args.set])
    # Absolute: saving the .blend makes the image paths relative to it, which breaks paths
    # that were relative to the working folder (the export then finds no pixels).
    out = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    for name in args.scenes:
        reset()
        mats = Materials(out / "textures")
        SCENES[name](mats)
        black_world()
        export(out, name)


if __name__ == "__main__":
    main()
