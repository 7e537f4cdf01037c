"""The test scenes of the Blender cross-check as plain data, and the regions they are judged on.

Everything here is pure Python (no bpy), so the scene specifications, the camera projection
that turns a region's world-space corners into a rectangle of the image, and the render
settings are unit-tested without Blender (tests/test_scenes.py). `build.py` turns a
`SceneSpec` into a .blend with bpy.

Coordinates are Blender's: metres, Z up. A camera looks from `location` at `target` with +Z up
in the image; a Blender camera's vertical field of view is `yfov_deg` (sensor fit vertical),
which the glTF exporter writes as `yfov`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

Vec3 = tuple[float, float, float]
Rgb = tuple[float, float, float]


@dataclass(frozen=True)
class Camera:
    """A perspective camera looking from `location` at `target`, +Z up."""

    location: Vec3
    target: Vec3
    yfov_deg: float


@dataclass(frozen=True)
class Texture:
    """A procedural image the builder writes as a PNG and wires into the Principled BSDF.

    `kind`: "bumps" (a tangent-space normal map of round bumps, for the Normal input through a
    Normal Map node), "puddles" (a greyscale roughness map: smooth puddles in rough asphalt),
    "fence" (an RGBA chain-link pattern whose alpha is 0 in the holes). `size` in pixels,
    `repeat` how often it tiles over the mesh's UV square (a Mapping node's scale, which the
    exporter writes as KHR_texture_transform).
    """

    kind: str
    size: int = 128
    repeat: float = 1.0


@dataclass(frozen=True)
class Material:
    """A Principled BSDF's inputs (Blender's names in the comments)."""

    name: str
    base_color: Rgb = (0.8, 0.8, 0.8)  # Base Color
    metallic: float = 0.0  # Metallic
    roughness: float = 0.5  # Roughness
    specular_ior_level: float = 0.5  # Specular IOR Level (0: no specular layer)
    ior: float = 1.5  # IOR
    coat_weight: float = 0.0  # Coat Weight
    coat_roughness: float = 0.03  # Coat Roughness
    transmission: float = 0.0  # Transmission Weight
    emission: Rgb = (0.0, 0.0, 0.0)  # Emission Color
    emission_strength: float = 0.0  # Emission Strength
    normal_map: Texture | None = None  # Normal (through a Normal Map node)
    roughness_map: Texture | None = None  # Roughness (the map's value)
    alpha_map: Texture | None = None  # Base Color and Alpha (alpha-clipped: glTF MASK)


@dataclass(frozen=True)
class Mesh:
    """A mesh: a quad (`points`: four corners, counter-clockwise seen from the front, the side
    its normal points to), a box (`points`: min and max corners) or a UV sphere (`points`:
    the centre; `radius`)."""

    name: str
    kind: str
    points: tuple[Vec3, ...]
    material: str
    radius: float = 0.0


@dataclass(frozen=True)
class Light:
    """A Blender lamp with zero radius (point, spot) or zero angle (sun).

    `power`: watts for point and spot lamps (Blender's Power), W/m^2 for the sun (Strength).
    `direction`: the way the light travels (spot axis, sun rays); the lamp's -Z points there.
    `spot_size_deg`: the spot's full cone angle (Blender's Spot Size); `spot_blend` its Blend.
    """

    name: str
    kind: str
    power: float
    color: Rgb = (1.0, 1.0, 1.0)
    location: Vec3 = (0.0, 0.0, 0.0)
    direction: Vec3 = (0.0, 0.0, -1.0)
    spot_size_deg: float = 45.0
    spot_blend: float = 0.15


#: The largest relative difference of a noiseless region (float rounding and the like).
NOISELESS_TOLERANCE = 1e-3


@dataclass(frozen=True)
class Region:
    """A patch of a surface, given by world-space points on it; judged on the image rectangle
    that bounds their projection (shrunk by `inset`, a fraction of its size on each side).
    `gate`: whether the check fails when this region disagrees; regions that measure a known
    model difference (a spot's penumbra) are reported but do not gate. `noiseless`: a region
    without Monte Carlo noise (an emitter seen directly), where the noise test means nothing
    (its standard error is 0); it is judged on `|relative bias| <= NOISELESS_TOLERANCE`."""

    name: str
    points: tuple[Vec3, ...]
    note: str
    gate: bool = True
    inset: float = 0.0
    noiseless: bool = False


@dataclass(frozen=True)
class SceneSpec:
    """A test scene: what the builder makes, how both renderers render it and where they are
    compared. `max_depth` has Mitsuba's meaning (2: direct light only), as `streaks render
    --max-depth`; Cycles gets `max_depth - 2` bounces."""

    name: str
    description: str
    camera: Camera
    materials: tuple[Material, ...]
    meshes: tuple[Mesh, ...]
    lights: tuple[Light, ...]
    regions: tuple[Region, ...]
    max_depth: int = 4
    width: int = 160
    height: int = 120
    spp: int = 256
    tolerance: float = 0.02
    notes: tuple[str, ...] = field(default_factory=tuple)

    def material(self, name: str) -> Material:
        """The material called `name`."""
        for m in self.materials:
            if m.name == name:
                return m
        raise KeyError(f"scene {self.name}: no material {name!r}")


def quad_xy(x0: float, y0: float, x1: float, y1: float, z: float) -> tuple[Vec3, ...]:
    """A horizontal rectangle at height `z`, facing up (+Z)."""
    return ((x0, y0, z), (x1, y0, z), (x1, y1, z), (x0, y1, z))


def quad_xz(x0: float, z0: float, x1: float, z1: float, y: float) -> tuple[Vec3, ...]:
    """A vertical rectangle in the plane y = `y`, facing -Y (toward a camera at smaller y)."""
    return ((x0, y, z0), (x1, y, z0), (x1, y, z1), (x0, y, z1))


def _normalize(v: Vec3) -> Vec3:
    n = math.sqrt(sum(c * c for c in v))
    return (v[0] / n, v[1] / n, v[2] / n)


def _cross(a: Vec3, b: Vec3) -> Vec3:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a: Vec3, b: Vec3) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def camera_basis(cam: Camera) -> tuple[Vec3, Vec3, Vec3]:
    """(right, up, forward) unit vectors of `cam` (+Z world up)."""
    fwd = _normalize(tuple(t - o for t, o in zip(cam.target, cam.location, strict=True)))  # type: ignore[arg-type]
    right = _normalize(_cross(fwd, (0.0, 0.0, 1.0)))
    up = _cross(right, fwd)
    return right, up, fwd


def project(cam: Camera, p: Vec3, aspect: float) -> tuple[float, float]:
    """The image position of `p` as fractions (x right, y down) of an image of width/height
    `aspect`; raises ValueError for a point behind the camera."""
    right, up, fwd = camera_basis(cam)
    d: Vec3 = (p[0] - cam.location[0], p[1] - cam.location[1], p[2] - cam.location[2])
    z = _dot(d, fwd)
    if z <= 0.0:
        raise ValueError(f"point {p} is behind the camera")
    t = math.tan(math.radians(cam.yfov_deg) / 2.0)
    ndc_x = _dot(d, right) / (z * t * aspect)
    ndc_y = _dot(d, up) / (z * t)
    return ((ndc_x + 1.0) / 2.0, (1.0 - ndc_y) / 2.0)


def region_fractions(
    cam: Camera, region: Region, aspect: float
) -> tuple[float, float, float, float]:
    """The rectangle (x0, y0, x1, y1), fractions of the image, y down, that bounds the
    projection of `region`'s points, shrunk by its inset and clipped to the image; raises
    ValueError when nothing of it is in the image."""
    pts = [project(cam, p, aspect) for p in region.points]
    x0, x1 = min(p[0] for p in pts), max(p[0] for p in pts)
    y0, y1 = min(p[1] for p in pts), max(p[1] for p in pts)
    dx, dy = (x1 - x0) * region.inset, (y1 - y0) * region.inset
    x0, x1, y0, y1 = x0 + dx, x1 - dx, y0 + dy, y1 - dy
    x0, y0 = max(x0, 0.0), max(y0, 0.0)
    x1, y1 = min(x1, 1.0), min(y1, 1.0)
    if x1 <= x0 or y1 <= y0:
        raise ValueError(f"region {region.name} is outside the image")
    return (x0, y0, x1, y1)


# --- (a) diffuse: the light units -------------------------------------------------------------

_FLOOR = Material("floor", base_color=(0.5, 0.5, 0.5), roughness=1.0, specular_ior_level=0.0)
_WALL = Material("wall", base_color=(0.6, 0.55, 0.5), roughness=1.0, specular_ior_level=0.0)


def emitter(name: str, colour: Rgb, strength: float) -> Material:
    """A black, non-reflecting Principled BSDF that emits `colour * strength` (radiance)."""
    return Material(
        name,
        base_color=(0.0, 0.0, 0.0),
        specular_ior_level=0.0,
        emission=colour,
        emission_strength=strength,
    )


_PANEL = emitter("panel", (1.0, 0.85, 0.6), 6.0)

POINT_AT: Vec3 = (-2.2, 0.5, 1.2)
SPOT_AT: Vec3 = (2.0, 0.6, 2.8)
SPOT_HALF_DEG = 30.0
SPOT_BLEND = 0.25


def _floor_square(cx: float, cy: float, half: float) -> tuple[Vec3, ...]:
    return quad_xy(cx - half, cy - half, cx + half, cy + half, 0.0)


def _spot_ring(radius: float, width: float) -> tuple[Vec3, ...]:
    """Floor points of a strip right of the spot at distances radius +- width/2 from its axis."""
    x, y = SPOT_AT[0], SPOT_AT[1]
    return quad_xy(x + radius - width / 2, y - 0.15, x + radius + width / 2, y + 0.15, 0.0)


def _diffuse(
    name: str,
    spot_blend: float,
    description: str,
    surfaces: tuple[Material, Material] = (_FLOOR, _WALL),
) -> SceneSpec:
    return SceneSpec(
        name=name,
        description=description,
        camera=Camera(location=(0.0, -7.0, 2.6), target=(0.0, 1.5, 0.9), yfov_deg=45.0),
        materials=(*surfaces, _PANEL),
        meshes=(
            Mesh("floor", "quad", quad_xy(-6.0, -4.0, 6.0, 4.0, 0.0), "floor"),
            Mesh("wall", "quad", quad_xz(-6.0, 0.0, 6.0, 4.5, 4.0), "wall"),
            Mesh("panel", "quad", quad_xz(-0.7, 1.6, 0.7, 2.4, 3.995), "panel"),
        ),
        lights=(
            Light("point", "point", power=40.0, color=(1.0, 0.9, 0.8), location=POINT_AT),
            Light(
                "spot",
                "spot",
                power=400.0,
                color=(0.8, 0.9, 1.0),
                location=SPOT_AT,
                direction=(0.0, 0.0, -1.0),
                spot_size_deg=2 * SPOT_HALF_DEG,
                spot_blend=spot_blend,
            ),
            Light("sun", "sun", power=0.4, color=(1.0, 0.95, 0.9), direction=(0.35, 0.45, -0.82)),
        ),
        regions=(
            Region("point", _floor_square(POINT_AT[0], POINT_AT[1], 0.5), "floor under the point"),
            Region("spot", _floor_square(SPOT_AT[0], SPOT_AT[1], 0.55), "floor in the spot's core"),
            Region(
                "spot_pen",
                _spot_ring(2.8 * math.tan(math.radians(27.0)), 0.3),
                "floor near the spot's edge (24.5-29.5 deg of its 30): with a blend, Cycles' "
                "smoothstep in cosine against glTF's t^2 between the exported inner and outer cones"
                if spot_blend > 0
                else "floor near the spot's edge (24.5-29.5 deg of its 30, hard edge)",
                gate=spot_blend == 0,
            ),
            Region(
                "panel",
                quad_xz(-0.6, 1.7, 0.6, 2.3, 3.995),
                "the emissive panel, seen directly (no noise: judged on |bias| <= 0.1%)",
                inset=0.1,
                noiseless=True,
            ),
            Region("floor_pn", quad_xy(-0.9, 2.5, 0.9, 3.7, 0.0), "floor lit by the panel"),
            Region("wall_sun", quad_xz(-5.0, 2.6, -3.2, 3.8, 4.0), "wall lit by the sun"),
        ),
        max_depth=4,
        width=160,
        height=120,
        spp=256,
        notes=(
            "Point and spot lamps: radius 0 and soft falloff off, so they are the exporter's "
            "point lights (Blender's sphere lamps are not punctual).",
        ),
    )


DIFFUSE = _diffuse(
    "diffuse",
    0.0,
    "A floor and a wall, both Principled BSDF with Specular IOR Level 0 (pure Lambert in "
    "Cycles), lit by a point lamp, a hard-edged spot lamp, a sun lamp and an emissive panel: "
    "checks the exporter's light units and cone angles against ours (the CI scene).",
)
SPOT_BLEND_SCENE = _diffuse(
    "spot_blend",
    SPOT_BLEND,
    "The diffuse scene with the spot's Blend at 0.25: measures the penumbra, where Cycles' "
    "falloff and the glTF falloff of the exported cones differ by design; the spot's extra "
    "light in Cycles' wider penumbra also reaches the other regions by interreflection.",
)

PRINCIPLED_SCENE = _diffuse(
    "principled",
    0.0,
    "The diffuse scene with Blender's default Principled BSDF on the floor and the wall "
    "(Specular IOR Level 0.5, roughness 0.5): measures Cycles' Principled BSDF against the "
    "glTF BRDF the export asks for (no material extension involved).",
    (
        Material("floor", base_color=_FLOOR.base_color),
        Material("wall", base_color=_WALL.base_color),
    ),
)

# --- (b) wet street: the material features --------------------------------------------------

_ROAD = Material(
    "road",
    base_color=(0.05, 0.05, 0.055),
    roughness=0.5,
    normal_map=Texture("bumps", size=128, repeat=8.0),
    roughness_map=Texture("puddles", size=128, repeat=2.0),
)
_PAINT = Material(
    "car_paint",
    base_color=(0.45, 0.02, 0.03),
    metallic=0.5,
    roughness=0.35,
    coat_weight=1.0,
    coat_roughness=0.03,
)
_GLASS = Material("glass", base_color=(1.0, 1.0, 1.0), roughness=0.0, transmission=1.0, ior=1.5)
_FENCE = Material("fence", roughness=0.6, alpha_map=Texture("fence", size=64, repeat=4.0))
_HEADLIGHT = emitter("headlight", (1.0, 0.95, 0.85), 40.0)
_BRICK = Material("building", base_color=(0.35, 0.3, 0.28), roughness=0.8)
_TYRE = Material("tyre", base_color=(0.02, 0.02, 0.02), roughness=0.9)

WET_STREET = SceneSpec(
    name="wet_street",
    description=(
        "A small wet street at night: a Principled BSDF road with a normal map (round bumps) "
        "and a roughness texture (smooth puddles), clear-coated car paint, a glass shelter "
        "pane (a 2 cm slab), an alpha-masked fence, headlights as emissive spheres, a street "
        "lamp (point), a spot and a weak moon (sun)."
    ),
    camera=Camera(location=(0.6, -1.5, 1.6), target=(0.0, 8.0, 0.7), yfov_deg=50.0),
    materials=(_ROAD, _PAINT, _GLASS, _FENCE, _HEADLIGHT, _BRICK, _TYRE),
    meshes=(
        Mesh("road", "quad", quad_xy(-4.0, -3.0, 4.0, 14.0, 0.0), "road"),
        Mesh(
            "building",
            "quad",
            ((4.0, -3.0, 0.0), (4.0, 14.0, 0.0), (4.0, 14.0, 5.0), (4.0, -3.0, 5.0)),
            "building",
        ),
        Mesh("back_wall", "quad", quad_xz(-4.0, 0.0, 4.0, 5.0, 13.0), "building"),
        Mesh("car", "box", ((-2.6, 5.0, 0.25), (-0.8, 9.0, 1.35)), "car_paint"),
        Mesh("tyres", "box", ((-2.5, 5.3, 0.0), (-0.9, 8.7, 0.25)), "tyre"),
        Mesh("shelter", "box", ((1.6, 3.0, 0.0), (3.6, 3.02, 2.2)), "glass"),
        Mesh("fence", "quad", quad_xz(-3.5, 0.0, 3.5, 2.0, 11.0), "fence"),
        Mesh("headlight_l", "sphere", ((-2.3, 4.97, 0.75),), "headlight", radius=0.12),
        Mesh("headlight_r", "sphere", ((-1.1, 4.97, 0.75),), "headlight", radius=0.12),
    ),
    lights=(
        Light(
            "street_lamp", "point", power=600.0, color=(1.0, 0.8, 0.55), location=(0.5, 7.0, 4.2)
        ),
        Light(
            "spot",
            "spot",
            power=1500.0,
            color=(0.85, 0.9, 1.0),
            location=(3.6, 2.0, 4.5),
            direction=(-4.6, 3.5, -4.5),
            spot_size_deg=50.0,
            spot_blend=0.0,
        ),
        Light("moon", "sun", power=0.05, color=(0.7, 0.8, 1.0), direction=(0.3, 0.5, -0.81)),
    ),
    regions=(
        Region(
            "road_near",
            quad_xy(-1.2, 1.0, 1.2, 2.5, 0.0),
            "road near the camera: normal "
            "map, roughness map, the spot's and the lamp's reflections",
        ),
        Region("road_lamp", quad_xy(-0.4, 6.2, 1.4, 7.8, 0.0), "road under the street lamp"),
        Region(
            "car_side",
            ((-0.8, 5.6, 0.4), (-0.8, 8.4, 0.4), (-0.8, 8.4, 1.2), (-0.8, 5.6, 1.2)),
            "car's right side: clear-coated paint",
        ),
        Region(
            "car_top",
            quad_xy(-2.4, 5.3, -1.0, 8.7, 1.35),
            "car's roof: paint seen at grazing angles (coat Fresnel)",
        ),
        Region(
            "headlight",
            ((-1.17, 4.85, 0.68), (-1.03, 4.85, 0.82)),
            "a headlight seen directly (emission)",
            noiseless=False,
        ),
        Region("glass", quad_xz(1.8, 0.3, 3.4, 2.0, 3.0), "the shelter pane: transmission"),
        Region(
            "fence",
            quad_xz(-2.8, 0.3, 2.8, 1.8, 11.0),
            "the fence: alpha mask over the lit back wall",
        ),
        Region(
            "building",
            ((4.0, 6.0, 3.0), (4.0, 10.0, 3.0), (4.0, 10.0, 4.5), (4.0, 6.0, 4.5)),
            "building front above the shelter, default Principled (Specular IOR Level 0.5), "
            "seen at grazing angles",
        ),
    ),
    max_depth=8,
    width=240,
    height=160,
    spp=256,
    tolerance=0.10,
)

# --- (c) the wet street's road alone: the normal map and the road's BRDF -----------------------


def _road_only(name: str, road: Material, description: str, tolerance: float) -> SceneSpec:
    """The wet street's road, camera and lamps, nothing else: no interreflection with the car,
    the shelter or the walls, so the road's regions measure the road's material alone."""
    return SceneSpec(
        name=name,
        description=description,
        camera=WET_STREET.camera,
        materials=(road,),
        meshes=(Mesh("road", "quad", quad_xy(-4.0, -3.0, 4.0, 14.0, 0.0), road.name),),
        lights=WET_STREET.lights,
        regions=tuple(r for r in WET_STREET.regions if r.name.startswith("road")),
        max_depth=WET_STREET.max_depth,
        width=WET_STREET.width,
        height=WET_STREET.height,
        spp=WET_STREET.spp,
        tolerance=tolerance,
    )


ROAD_LAMBERT = _road_only(
    "road_lambert",
    Material(
        "road",
        base_color=(0.5, 0.5, 0.5),
        roughness=1.0,
        specular_ior_level=0.0,
        normal_map=_ROAD.normal_map,
    ),
    "The wet street's road alone, a Lambertian grey (Specular IOR Level 0) with the road's "
    "normal map of round bumps: checks the tangent frame, the normal map's orientation and the "
    "shading-normal rules against Cycles', with no model difference in the BRDF.",
    0.02,
)
ROAD_ONLY = _road_only(
    "road_only",
    _ROAD,
    "The wet street's road alone, its material as in the street (normal map, roughness map, "
    "Specular IOR Level 0.5): measures Cycles' Principled BSDF against the glTF BRDF on a "
    "dark, bumpy, partly glossy road seen at grazing angles.",
    0.10,
)

# --- (d) the wet street's car paint on the diffuse scene's floor and wall ---------------------


def _paint(name: str, paint: Material, description: str) -> SceneSpec:
    """The diffuse scene with `paint` on the floor (seen at 70-75 degrees) and the wall (seen
    nearly head-on): the car paint's parts, one at a time, against Cycles' Principled BSDF."""
    return _diffuse(
        name,
        0.0,
        description,
        (replace(paint, name="floor"), replace(paint, name="wall")),
    )


PAINT_SCENES = (
    _paint("paint", _PAINT, "The wet street's car paint (metallic 0.5, clear coat 1)."),
    _paint(
        "paint_base",
        replace(_PAINT, metallic=0.0, coat_weight=0.0),
        "The car paint's dielectric base alone (metallic 0, no coat): the layering of the "
        "glTF BRDF (diffuse times 1 - F(v.h)) against Cycles' (times 1 - E(mu_o)).",
    ),
    _paint(
        "paint_metal",
        replace(_PAINT, metallic=1.0, coat_weight=0.0),
        "The car paint's metal alone (metallic 1, no coat): Schlick's conductor Fresnel "
        "against Cycles' F82 tint.",
    ),
)

SCENES: dict[str, SceneSpec] = {
    s.name: s
    for s in (
        DIFFUSE,
        SPOT_BLEND_SCENE,
        PRINCIPLED_SCENE,
        WET_STREET,
        ROAD_LAMBERT,
        ROAD_ONLY,
        *PAINT_SCENES,
    )
}


def cycles_bounces(max_depth: int) -> int:
    """Cycles' Max Bounces for a path of at most `max_depth` segments (Mitsuba's meaning: 1
    emitters only, 2 direct light): Cycles counts the bounces after the first hit, whose
    direct light it always computes, so `max_depth - 2`."""
    if max_depth < 2:
        raise ValueError(f"max depth {max_depth}: the cross-check needs at least direct light (2)")
    return max_depth - 2
