"""Builds a `scenes.SceneSpec` in Blender (bpy), saves the .blend, exports it with Blender's glTF
exporter and renders it with Cycles.

Run inside the Python that has `bpy` (tools/blender/requirements.txt). The export uses the
exporter's default settings except the two Include choices a user ticks to export a street at
all, cameras and punctual lights (`export_cameras`, `export_lights`; both off by default);
nothing touches its unit conversion (`export_import_convert_lighting_mode` stays "SPEC",
physically based).

Cycles renders with what an unbiased comparison needs (see README.md): CPU, no denoising, no
clamping, no glossy filter, no light threshold, no adaptive sampling, a one-pixel box filter,
a black world, a fixed seed, an independent-per-pixel sampling pattern, the Standard view
transform, and a linear Rec.709 float EXR.
"""

from __future__ import annotations

import math
from pathlib import Path

import bpy  # type: ignore[import-not-found]
import numpy as np
from mathutils import Vector  # type: ignore[import-not-found]

from scenes import (
    Camera,
    Light,
    Material,
    Mesh,
    SceneSpec,
    Texture,
    cycles_bounces,
)


def reset() -> None:
    """An empty scene (no default cube, camera or lamp)."""
    bpy.ops.wm.read_factory_settings(use_empty=True)


# --- textures ---------------------------------------------------------------------------------


def texture_pixels(tex: Texture) -> np.ndarray:
    """The RGBA pixels (size x size x 4, floats in [0, 1], row 0 at the bottom as Blender
    stores them) of a procedural texture."""
    n = tex.size
    v, u = np.mgrid[0:n, 0:n].astype(np.float64)
    u, v = (u + 0.5) / n, (v + 0.5) / n
    out = np.ones((n, n, 4))
    if tex.kind == "bumps":
        # Round bumps on a 4x4 grid: height h = cos^2 of the distance to the cell centre;
        # tangent-space normal (-dh/du, -dh/dv, 1), encoded as n/2 + 1/2.
        cu, cv = (u * 4) % 1.0 - 0.5, (v * 4) % 1.0 - 0.5
        r = np.sqrt(cu * cu + cv * cv)
        inside = r < 0.4
        slope = np.where(inside, 1.5 * np.sin(np.pi * r / 0.4), 0.0)
        with np.errstate(invalid="ignore", divide="ignore"):
            nx = np.where(inside & (r > 0), slope * cu / r, 0.0)
            ny = np.where(inside & (r > 0), slope * cv / r, 0.0)
        length = np.sqrt(nx * nx + ny * ny + 1.0)
        out[..., 0] = 0.5 + 0.5 * nx / length
        out[..., 1] = 0.5 + 0.5 * ny / length
        out[..., 2] = 0.5 + 0.5 / length
    elif tex.kind == "puddles":
        # Roughness in G (glTF's metallicRoughness channel), metallic 0 in B: 0.08 in three
        # round puddles, 0.7 elsewhere.
        rough = np.full((n, n), 0.7)
        for pu, pv, pr in ((0.3, 0.35, 0.18), (0.7, 0.6, 0.14), (0.45, 0.8, 0.1)):
            rough[(u - pu) ** 2 + (v - pv) ** 2 < pr * pr] = 0.08
        out[..., 0] = 1.0
        out[..., 1] = rough
        out[..., 2] = 0.0
    elif tex.kind == "fence":
        # A grey wire grid (8 cells), alpha 0 in the holes.
        cu, cv = (u * 8) % 1.0, (v * 8) % 1.0
        wire = (cu < 0.2) | (cv < 0.2)
        out[..., 0:3] = 0.6
        out[..., 3] = np.where(wire, 1.0, 0.0)
    else:
        raise ValueError(f"unknown texture kind {tex.kind!r}")
    return out


def make_image(name: str, tex: Texture, folder: Path, non_color: bool) -> bpy.types.Image:
    """The texture as a PNG in `folder`, loaded as a Blender image."""
    folder.mkdir(parents=True, exist_ok=True)
    img = bpy.data.images.new(name, tex.size, tex.size, alpha=True, float_buffer=False)
    img.pixels.foreach_set(texture_pixels(tex).astype(np.float32).ravel())
    img.filepath_raw = str(folder / f"{name}.png")
    img.file_format = "PNG"
    img.save()
    img = bpy.data.images.load(str(folder / f"{name}.png"), check_existing=False)
    if non_color:
        img.colorspace_settings.name = "Non-Color"
    return img


def image_node(nodes, links, img: bpy.types.Image, tex: Texture, x: float, y: float, mapping: bool):
    """An Image Texture node reading `img` through UV coordinates scaled by `tex.repeat` (a
    Mapping node, exported as KHR_texture_transform) when it repeats and `mapping` is set
    (otherwise the mesh's UVs carry the repeat: `uv_repeat`)."""
    node = nodes.new("ShaderNodeTexImage")
    node.image = img
    node.interpolation = "Linear"
    node.location = (x, y)
    if tex.repeat != 1.0 and mapping:
        coords = nodes.new("ShaderNodeTexCoord")
        coords.location = (x - 400, y)
        mapping = nodes.new("ShaderNodeMapping")
        mapping.location = (x - 200, y)
        mapping.inputs["Scale"].default_value = (tex.repeat, tex.repeat, 1.0)
        links.new(coords.outputs["UV"], mapping.inputs["Vector"])
        links.new(mapping.outputs["Vector"], node.inputs["Vector"])
    return node


# --- materials, meshes, lamps, camera ---------------------------------------------------------


def uv_repeat(m: Material, mapping: bool) -> float:
    """How far a mesh's UVs reach (0..repeat) for material `m`: 1 with Mapping nodes, else the
    largest repeat of its textures."""
    if mapping:
        return 1.0
    maps = (m.normal_map, m.roughness_map, m.alpha_map)
    return max([t.repeat for t in maps if t is not None], default=1.0)


def make_material(m: Material, tex_folder: Path, mapping: bool) -> bpy.types.Material:
    """A Principled BSDF material with `m`'s inputs and textures (repeated by Mapping nodes
    when `mapping`, else by the meshes' UVs)."""
    mat = bpy.data.materials.new(m.name)
    if not mat.node_tree:
        mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes["Principled BSDF"]
    inputs = bsdf.inputs
    inputs["Base Color"].default_value = (*m.base_color, 1.0)
    inputs["Metallic"].default_value = m.metallic
    inputs["Roughness"].default_value = m.roughness
    inputs["Specular IOR Level"].default_value = m.specular_ior_level
    inputs["IOR"].default_value = m.ior
    inputs["Coat Weight"].default_value = m.coat_weight
    inputs["Coat Roughness"].default_value = m.coat_roughness
    inputs["Transmission Weight"].default_value = m.transmission
    inputs["Emission Color"].default_value = (*m.emission, 1.0)
    inputs["Emission Strength"].default_value = m.emission_strength
    if m.normal_map is not None:
        img = make_image(f"{m.name}_normal", m.normal_map, tex_folder, non_color=True)
        node = image_node(nodes, links, img, m.normal_map, -700, -500, mapping)
        nmap = nodes.new("ShaderNodeNormalMap")
        nmap.location = (-300, -500)
        links.new(node.outputs["Color"], nmap.inputs["Color"])
        links.new(nmap.outputs["Normal"], inputs["Normal"])
    if m.roughness_map is not None:
        # As Blender's glTF importer wires a metallicRoughness texture: G roughness, B metallic.
        img = make_image(f"{m.name}_roughness", m.roughness_map, tex_folder, non_color=True)
        node = image_node(nodes, links, img, m.roughness_map, -700, 0, mapping)
        sep = nodes.new("ShaderNodeSeparateColor")
        sep.location = (-300, 0)
        links.new(node.outputs["Color"], sep.inputs["Color"])
        links.new(sep.outputs["Green"], inputs["Roughness"])
        links.new(sep.outputs["Blue"], inputs["Metallic"])
    if m.alpha_map is not None:
        # Alpha clip as Blender's glTF importer builds it for alphaMode MASK (cutoff 0.5):
        # alpha -> Math (1 - (a < 0.5)) -> Alpha, which the exporter writes back as MASK.
        img = make_image(f"{m.name}_alpha", m.alpha_map, tex_folder, non_color=False)
        node = image_node(nodes, links, img, m.alpha_map, -700, 400, mapping)
        links.new(node.outputs["Color"], inputs["Base Color"])
        less = nodes.new("ShaderNodeMath")
        less.operation = "LESS_THAN"
        less.inputs[1].default_value = 0.5
        less.location = (-400, 300)
        flip = nodes.new("ShaderNodeMath")
        flip.operation = "SUBTRACT"
        flip.inputs[0].default_value = 1.0
        flip.location = (-250, 300)
        links.new(node.outputs["Alpha"], less.inputs[0])
        links.new(less.outputs[0], flip.inputs[1])
        links.new(flip.outputs[0], inputs["Alpha"])
    return mat


def box_geometry(lo: tuple[float, ...], hi: tuple[float, ...]):
    """Vertices and outward-wound faces of the box with corners `lo` and `hi`."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    verts = [(x, y, z) for z in (z0, z1) for y in (y0, y1) for x in (x0, x1)]
    faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    return verts, faces


def make_mesh(m: Mesh, materials: dict[str, bpy.types.Material], repeat: float) -> bpy.types.Object:
    """The object for `m`, with UVs (a quad's corners get (0,0), (r,0), (r,r), (0,r) for the
    repeat r)."""
    if m.kind == "sphere":
        bpy.ops.mesh.primitive_uv_sphere_add(
            segments=32, ring_count=16, radius=m.radius, location=m.points[0]
        )
        obj = bpy.context.active_object
        obj.name = m.name
        bpy.ops.object.shade_smooth()
    else:
        if m.kind == "quad":
            verts, faces = list(m.points), [(0, 1, 2, 3)]
        elif m.kind == "box":
            verts, faces = box_geometry(m.points[0], m.points[1])
        else:
            raise ValueError(f"mesh {m.name}: unknown kind {m.kind!r}")
        me = bpy.data.meshes.new(m.name)
        me.from_pydata(verts, [], faces)
        uv = me.uv_layers.new(name="UVMap")
        r = repeat
        corners = [(0.0, 0.0), (r, 0.0), (r, r), (0.0, r)]
        for poly in me.polygons:
            for k, li in enumerate(poly.loop_indices):
                uv.data[li].uv = corners[k % 4]
        me.update()
        obj = bpy.data.objects.new(m.name, me)
        bpy.context.scene.collection.objects.link(obj)
    obj.data.materials.append(materials[m.material])
    return obj


def point_along(obj: bpy.types.Object, direction: tuple[float, ...]) -> None:
    """Turns `obj` so that its local -Z points along `direction` (lamps, cameras)."""
    obj.rotation_mode = "QUATERNION"
    obj.rotation_quaternion = Vector(direction).to_track_quat("-Z", "Y")


def make_light(spec: Light) -> bpy.types.Object:
    """A point, spot or sun lamp with zero size and soft falloff off (a punctual light)."""
    kind = {"point": "POINT", "spot": "SPOT", "sun": "SUN"}[spec.kind]
    lamp = bpy.data.lights.new(spec.name, kind)
    lamp.color = spec.color
    lamp.energy = spec.power
    if kind == "SUN":
        lamp.angle = 0.0
    else:
        lamp.shadow_soft_size = 0.0
        lamp.use_soft_falloff = False
    if kind == "SPOT":
        lamp.spot_size = math.radians(spec.spot_size_deg)
        lamp.spot_blend = spec.spot_blend
        lamp.show_cone = True
    obj = bpy.data.objects.new(spec.name, lamp)
    obj.location = spec.location
    point_along(obj, spec.direction)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def make_camera(spec: Camera) -> bpy.types.Object:
    """The scene camera (sensor fit vertical, so `yfov_deg` is its vertical field of view)."""
    cam = bpy.data.cameras.new("cam")
    cam.sensor_fit = "VERTICAL"
    cam.angle_y = math.radians(spec.yfov_deg)
    cam.clip_start = 0.05
    obj = bpy.data.objects.new("cam", cam)
    obj.location = spec.location
    point_along(obj, tuple(t - o for t, o in zip(spec.target, spec.location, strict=True)))
    bpy.context.scene.collection.objects.link(obj)
    bpy.context.scene.camera = obj
    return obj


def black_world() -> None:
    """A world that emits nothing."""
    world = bpy.data.worlds.new("black")
    world.color = (0.0, 0.0, 0.0)
    if world.node_tree is not None:
        bg = world.node_tree.nodes.get("Background")
        if bg is not None:
            bg.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
            bg.inputs["Strength"].default_value = 0.0
    bpy.context.scene.world = world


# --- render settings --------------------------------------------------------------------------


def cycles_settings(width: int, height: int, spp: int, max_depth: int) -> None:
    """Cycles and colour-management settings for an unbiased, linear render (module docs)."""
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.render.resolution_x = width
    scene.render.resolution_y = height
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.render.use_compositing = False
    scene.render.use_sequencer = False
    c = scene.cycles
    c.device = "CPU"
    c.samples = spp
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.light_sampling_threshold = 0.0
    # A one-pixel box: each pixel averages its own square, as streaks and Mitsuba's box do.
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    # Independent noise per pixel (the noise test assumes it; blue noise correlates pixels).
    c.sampling_pattern = "TABULATED_SOBOL"
    c.use_animated_seed = False
    bounces = cycles_bounces(max_depth)
    c.max_bounces = bounces
    c.diffuse_bounces = bounces
    c.glossy_bounces = bounces
    c.transmission_bounces = bounces
    c.volume_bounces = 0
    c.transparent_max_bounces = 64
    c.caustics_reflective = True
    c.caustics_refractive = True
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    img = scene.render.image_settings
    img.file_format = "OPEN_EXR"
    img.color_mode = "RGB"
    img.color_depth = "32"
    img.exr_codec = "ZIP"


def colour_management() -> dict[str, str]:
    """What the EXR's pixels are in: the working space, the view, the EXR's colour space."""
    scene = bpy.context.scene
    img = scene.render.image_settings
    return {
        "working_space": bpy.data.colorspace.working_space,
        "view_transform": scene.view_settings.view_transform,
        "look": scene.view_settings.look,
        "exr_colorspace": img.linear_colorspace_settings.name,
        "exr_color_management": img.color_management,
    }


def build(
    spec: SceneSpec,
    out: Path,
    width: int,
    height: int,
    spp: int,
    max_depth: int,
    mapping: bool = True,
) -> tuple[Path, Path]:
    """Builds `spec` (rendered at `max_depth`, Mitsuba's meaning; textures repeated by Mapping
    nodes when `mapping`, else by UVs), saves `out/<name>.blend` and exports
    `out/<name>.glb`; returns both."""
    out.mkdir(parents=True, exist_ok=True)
    reset()
    tex_folder = out / "textures"
    materials = {m.name: make_material(m, tex_folder, mapping) for m in spec.materials}
    for mesh in spec.meshes:
        make_mesh(mesh, materials, uv_repeat(spec.material(mesh.material), mapping))
    for light in spec.lights:
        make_light(light)
    make_camera(spec.camera)
    black_world()
    cycles_settings(width, height, spp, max_depth)
    blend = out / f"{spec.name}.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    glb = out / f"{spec.name}.glb"
    bpy.ops.export_scene.gltf(filepath=str(glb), export_cameras=True, export_lights=True)
    return blend, glb


def render(path: Path, seed: int) -> None:
    """Renders the current scene with Cycles with `seed` to the EXR `path`."""
    scene = bpy.context.scene
    scene.cycles.seed = seed
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
