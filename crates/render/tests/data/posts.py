# Writes posts.gltf (tests/data/README.md): a ground quad, a box mesh placed by 12 nodes (rotated, scaled, one
# mirrored) and an emissive box placed by 3 nodes, a camera, a point and a sun light.
import base64, json, math, struct
bin_ = bytearray()
views, accessors = [], []
def add(data, fmt, ty, count, minmax=None):
    while len(bin_) % 4: bin_.append(0)
    off = len(bin_); bin_.extend(struct.pack('<' + fmt * (len(data)), *data))
    views.append({"buffer": 0, "byteOffset": off, "byteLength": len(bin_) - off})
    a = {"bufferView": len(views) - 1, "componentType": 5126 if fmt == 'f' else 5123, "count": count, "type": ty}
    if minmax: a["min"], a["max"] = minmax
    accessors.append(a); return len(accessors) - 1
def cross(a, b): return [a[1]*b[2]-a[2]*b[1], a[2]*b[0]-a[0]*b[2], a[0]*b[1]-a[1]*b[0]]
pos, nrm, idx = [], [], []
for n, t in [([1,0,0],[0,0,1]), ([-1,0,0],[0,1,0]), ([0,1,0],[1,0,0]), ([0,-1,0],[0,0,1]), ([0,0,1],[0,1,0]), ([0,0,-1],[1,0,0])]:
    b = cross(n, t); o = len(pos) // 3
    for x, y in [(-1,-1),(1,-1),(1,1),(-1,1)]:
        pos += [0.5*(n[k] + x*t[k] + y*b[k]) for k in range(3)]; nrm += n
    idx += [o, o+1, o+2, o, o+2, o+3]
box = {"POSITION": add(pos, 'f', "VEC3", 24, ([-0.5]*3, [0.5]*3)), "NORMAL": add(nrm, 'f', "VEC3", 24)}
box_idx = add(idx, 'H', "SCALAR", 36)
g = [-6,0,-6, -6,0,6, 6,0,6, 6,0,-6]
ground = {"POSITION": add(g, 'f', "VEC3", 4, ([-6,0,-6],[6,0,6])), "NORMAL": add([0,1,0]*4, 'f', "VEC3", 4)}
ground_idx = add([0,1,2,0,2,3], 'H', "SCALAR", 6)
def quat(axis, angle):
    s = math.sin(angle/2); l = math.sqrt(sum(a*a for a in axis))
    return [a/l*s for a in axis] + [math.cos(angle/2)]
nodes = [{"name": "ground", "mesh": 0}]
for i in range(12):
    x = -4.5 + (i % 6) * 1.8; z = -1.5 if i < 6 else 1.0
    n = {"name": f"post{i}", "mesh": 1, "translation": [x, 0.75 + 0.1*i, z],
         "rotation": quat([0.2*i, 1, 0.1], 0.4*i), "scale": [0.4 + 0.03*i, 1.5, 0.3 + 0.05*(i % 3)]}
    if i == 7: n["scale"][0] = -n["scale"][0]
    nodes.append(n)
for i in range(3):
    nodes.append({"name": f"lamp{i}", "mesh": 2, "translation": [-3 + 3*i, 3.0, -3.0], "scale": [0.3, 0.2, 0.3]})
nodes.append({"name": "camera", "camera": 0, "translation": [0, 3.5, 9], "rotation": quat([1,0,0], -0.3)})
nodes.append({"name": "bulb", "translation": [1, 4, 2], "extensions": {"KHR_lights_punctual": {"light": 0}}})
nodes.append({"name": "sun", "rotation": quat([1, 0.3, 0], -1.0), "extensions": {"KHR_lights_punctual": {"light": 1}}})
doc = {
    "asset": {"version": "2.0", "generator": "streaks tests/data (posts)"},
    "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength"],
    "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}],
    "nodes": nodes,
    "meshes": [
        {"name": "ground", "primitives": [{"attributes": ground, "indices": ground_idx, "material": 0}]},
        {"name": "post", "primitives": [{"attributes": box, "indices": box_idx, "material": 1}]},
        {"name": "lamp", "primitives": [{"attributes": box, "indices": box_idx, "material": 2}]},
    ],
    "materials": [
        {"name": "asphalt", "pbrMetallicRoughness": {"baseColorFactor": [0.3, 0.3, 0.3, 1], "metallicFactor": 0, "roughnessFactor": 0.4}},
        {"name": "paint", "pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.3, 0.1, 1], "metallicFactor": 0.5, "roughnessFactor": 0.3}},
        {"name": "glow", "emissiveFactor": [1, 0.9, 0.7], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 20}}},
    ],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "aspectRatio": 1.5}}],
    "extensions": {"KHR_lights_punctual": {"lights": [
        {"type": "point", "color": [1, 0.8, 0.6], "intensity": 3000},
        {"type": "directional", "intensity": 300}]}},
    "buffers": [{"byteLength": len(bin_), "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(bin_)).decode()}],
    "bufferViews": views, "accessors": accessors,
}
open("posts.gltf", "w").write(json.dumps(doc, indent=1))
