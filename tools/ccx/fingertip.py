"""Fingertip model geometry for the CalculiX reference tools (standard library only).

Reads a model YAML (config/models/X.yaml) and its Gmsh MSH 4.1 ASCII mesh and derives the
same sets the C++ loader (src/model/fingertip_model.cpp) derives:

  soft tets (epidermis, dermis, subcutaneous, soft_tissue) positively oriented,
  rigid tets (bone, nail), attached nodes (soft nodes that are also rigid nodes),
  skin triangles (free faces of the soft mesh that are not faces of a rigid tet, outward),
  Merkel triangles (faces shared by an epidermis and a dermis tet, normal dermis -> epidermis),
  stratum corneum triangles (surface group, model A), the pad frame (15 deg tilt).

Node ids are Gmsh node tags throughout. Coordinates are in mm (the CalculiX deck is in
mm, N, MPa, so SED comes out in MPa = 1e6 Pa).
"""
import math
import os

SOFT = ("epidermis", "dermis", "subcutaneous", "soft_tissue")
RIGID = ("bone", "nail")
# Faces of a positively oriented tet, outward (same table as the C++ loader).
FACE_VERTICES = ((1, 2, 3), (0, 3, 2), (0, 1, 3), (0, 2, 1))


class ModelError(Exception):
    pass


# ---------------------------------------------------------------- minimal YAML
def _scalar(text):
    text = text.strip()
    if len(text) >= 2 and text[0] == text[-1] and text[0] in "'\"":
        return text[1:-1]
    for conv in (int, float):
        try:
            return conv(text)
        except ValueError:
            pass
    if text in ("true", "false"):
        return text == "true"
    return text


def _strip_comment(line):
    out, quote = [], None
    for ch in line:
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch == "#":
            break
        out.append(ch)
    return "".join(out).rstrip()


def _flow_map(text):
    body = text.strip()[1:-1]
    result = {}
    for item in body.split(","):
        if not item.strip():
            continue
        k, _, v = item.partition(":")
        result[k.strip()] = _scalar(v)
    return result


def read_simple_yaml(path):
    """Block mappings of scalars and one-line flow mappings: what the model YAMLs use."""
    root = {}
    stack = [(-1, root)]
    with open(path) as f:
        for number, raw in enumerate(f, 1):
            line = _strip_comment(raw)
            if not line.strip():
                continue
            indent = len(line) - len(line.lstrip(" "))
            key, sep, value = line.strip().partition(":")
            if not sep:
                raise ModelError(f"{path}:{number}: cannot read '{line.strip()}'")
            while stack and indent <= stack[-1][0]:
                stack.pop()
            parent = stack[-1][1]
            value = value.strip()
            if not value:
                parent[key] = {}
                stack.append((indent, parent[key]))
            elif value.startswith("{"):
                parent[key] = _flow_map(value)
            else:
                parent[key] = _scalar(value)
    return root


# ---------------------------------------------------------------- MSH 4.1
def read_msh(path):
    """Returns dict(nodes={tag: (x,y,z)}, names={(dim,tag): name},
    entity_phys={(dim,tag): [phys]}, elements=[(dim, entity, type, tag, [node tags])])."""
    with open(path) as f:
        lines = f.read().split("\n")
    i = 0
    names, entity_phys, nodes, elements = {}, {}, {}, []

    def nxt():
        nonlocal i
        while i < len(lines) and not lines[i].strip():
            i += 1
        if i >= len(lines):
            raise ModelError(f"{path}: unexpected end of file")
        s = lines[i]
        i += 1
        return s

    while i < len(lines):
        s = lines[i].strip()
        i += 1
        if s == "$MeshFormat":
            v = nxt().split()
            if not v[0].startswith("4.1") or v[1] != "0":
                raise ModelError(f"{path}: need MSH 4.1 ASCII, got version {v[0]} file-type {v[1]}")
        elif s == "$PhysicalNames":
            for _ in range(int(nxt())):
                parts = nxt().split(None, 2)
                names[(int(parts[0]), int(parts[1]))] = parts[2].strip().strip('"')
        elif s == "$Entities":
            counts = [int(t) for t in nxt().split()]
            for dim in range(4):
                for _ in range(counts[dim]):
                    t = nxt().split()
                    tag = int(t[0])
                    k = 4 if dim == 0 else 7
                    nphys = int(t[k])
                    entity_phys[(dim, tag)] = [int(p) for p in t[k + 1:k + 1 + nphys]]
        elif s == "$Nodes":
            nblocks = int(nxt().split()[0])
            for _ in range(nblocks):
                _, _, parametric, n = (int(t) for t in nxt().split())
                tags = [int(nxt()) for _ in range(n)]
                for tag in tags:
                    c = nxt().split()
                    nodes[tag] = (float(c[0]), float(c[1]), float(c[2]))
        elif s == "$Elements":
            nblocks = int(nxt().split()[0])
            for _ in range(nblocks):
                dim, ent, etype, n = (int(t) for t in nxt().split())
                for _ in range(n):
                    t = [int(v) for v in nxt().split()]
                    elements.append((dim, ent, etype, t[0], t[1:]))
    if not nodes or not elements:
        raise ModelError(f"{path}: no nodes or elements")
    return dict(nodes=nodes, names=names, entity_phys=entity_phys, elements=elements)


# ---------------------------------------------------------------- vectors
def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def signed_volume(p0, p1, p2, p3):
    return dot(cross(sub(p1, p0), sub(p2, p0)), sub(p3, p0)) / 6.0


# ---------------------------------------------------------------- model
class Model:
    """A fingertip model; coordinates in mm, ids are Gmsh tags."""

    def __init__(self):
        self.name = ""
        self.nodes = {}          # tag -> model-frame position [mm]
        self.soft_tets = []      # (element tag, tissue, [4 node tags]) positive
        self.rigid_tets = []     # (element tag, tissue, [4 node tags])
        self.materials = {}      # tissue -> dict(E_MPa, nu)
        self.attached = []       # soft node tags on bone/nail
        self.skin = []           # outward triangles (node tags)
        self.merkel = []         # dermis -> epidermis triangles
        self.sc = []             # stratum corneum triangles (outward, as the skin)
        self.sc_thickness_mm = 0.0
        self.sc_material = None
        self.tilt_deg = 15.0
        self.origin = (0.0, 0.0, 0.0)
        self.soft_nodes = []     # sorted tags

    # pad frame: x_pad = (1,0,0), y_pad = (0,cos t,-sin t), z_pad = (0,sin t,cos t)
    def axes(self):
        t = math.radians(self.tilt_deg)
        return (1.0, 0.0, 0.0), (0.0, math.cos(t), -math.sin(t)), (0.0, math.sin(t), math.cos(t))

    def to_pad(self, p):
        ex, ey, ez = self.axes()
        d = sub(p, self.origin)
        return (dot(ex, d), dot(ey, d), dot(ez, d))

    def pad_positions(self):
        return {tag: self.to_pad(self.nodes[tag]) for tag in self.soft_nodes}

    def merkel_nodes(self):
        return sorted({n for t in self.merkel for n in t})

    def skin_nodes(self):
        return sorted({n for t in self.skin for n in t})


def _material(entry, where):
    try:
        return dict(E_MPa=float(entry["youngs_modulus_MPa"]), nu=float(entry["poisson_ratio"]))
    except (KeyError, TypeError, ValueError):
        raise ModelError(f"{where}: material needs youngs_modulus_MPa and poisson_ratio")


TABLE_II = {
    "epidermis": dict(E_MPa=0.136, nu=0.48), "dermis": dict(E_MPa=0.08, nu=0.48),
    "subcutaneous": dict(E_MPa=0.034, nu=0.48), "soft_tissue": dict(E_MPa=0.034, nu=0.48),
    "stratum_corneum": dict(E_MPa=1.993, nu=0.48),
}


def resolve_model_path(name_or_path, repo_root):
    if os.path.sep not in name_or_path and "." not in name_or_path:
        return os.path.join(repo_root, "config", "models", name_or_path + ".yaml")
    return name_or_path


def load_model(name_or_path, repo_root):
    path = resolve_model_path(name_or_path, repo_root)
    if not os.path.exists(path):
        raise ModelError(f"model '{name_or_path}': {path} does not exist")
    m = Model()
    if path.endswith((".yaml", ".yml")):
        y = read_simple_yaml(path)
        m.name = str(y.get("name", os.path.splitext(os.path.basename(path))[0]))
        mesh = os.path.join(os.path.dirname(path), str(y["mesh"]))
        unit = {"mm": 1.0, "m": 1000.0}[str(y.get("mesh_unit", "mm"))]
        for k, v in (y.get("materials") or {}).items():
            m.materials[k] = _material(v, f"{path}: materials.{k}")
        m.tilt_deg = float((y.get("pad_frame") or {}).get("tilt_deg", 15.0))
        m.sc_thickness_mm = float((y.get("layers") or {}).get("stratum_corneum_mm", 0.0))
    else:
        m.name = os.path.splitext(os.path.basename(path))[0]
        mesh, unit = path, 1.0
        m.materials = {k: dict(v) for k, v in TABLE_II.items()}
        m.sc_thickness_mm = 0.02
    msh = read_msh(mesh)
    _build(m, msh, unit, mesh)
    return m


def _build(m, msh, unit, mesh_path):
    names = msh["names"]
    for tag, p in msh["nodes"].items():
        m.nodes[tag] = (p[0] * unit, p[1] * unit, p[2] * unit)
    sc_tris = []
    for dim, ent, etype, etag, conn in msh["elements"]:
        phys = msh["entity_phys"].get((dim, ent), [])
        groups = [names.get((dim, p), "") for p in phys]
        if dim == 3:
            tissue = [g for g in groups if g in SOFT + RIGID]
            if len(tissue) != 1 or etype != 4:
                raise ModelError(f"{mesh_path}: element {etag} (type {etype}) groups {groups}")
            n = conn[:4]
            p = [m.nodes[t] for t in n]
            if signed_volume(*p) < 0:
                n = [n[0], n[2], n[1], n[3]]
            (m.soft_tets if tissue[0] in SOFT else m.rigid_tets).append((etag, tissue[0], n))
        elif dim == 2 and "stratum_corneum" in groups:
            sc_tris.append(conn[:3])
    soft = set()
    for _, _, n in m.soft_tets:
        soft.update(n)
    rigid = set()
    rigid_faces = set()
    for _, _, n in m.rigid_tets:
        rigid.update(n)
        for f in FACE_VERTICES:
            rigid_faces.add(tuple(sorted(n[i] for i in f)))
    m.soft_nodes = sorted(soft)
    m.attached = sorted(soft & rigid)
    faces = {}
    for k, (_, tissue, n) in enumerate(m.soft_tets):
        for f in FACE_VERTICES:
            tri = (n[f[0]], n[f[1]], n[f[2]])
            faces.setdefault(tuple(sorted(tri)), []).append((k, tri))
    skin = {}
    for key in sorted(faces):
        uses = faces[key]
        if len(uses) == 1:
            if key not in rigid_faces:
                skin[key] = uses[0][1]
            continue
        a, b = (m.soft_tets[u[0]][1] for u in uses)
        if {a, b} == {"epidermis", "dermis"}:
            m.merkel.append(uses[0][1] if a == "dermis" else uses[1][1])
    m.skin = [skin[k] for k in sorted(skin)]
    for t in sc_tris:
        key = tuple(sorted(t))
        if key not in skin:
            raise ModelError(f"{mesh_path}: stratum_corneum triangle {t} is not a skin face")
        m.sc.append(skin[key])
    if m.sc:
        m.sc_material = m.materials.get("stratum_corneum", TABLE_II["stratum_corneum"])
        if m.sc_thickness_mm <= 0:
            m.sc_thickness_mm = 0.02
    used = {t for _, t, _ in m.soft_tets}
    for t in used:
        if t not in m.materials:
            raise ModelError(f"model {m.name}: no material for soft group '{t}'")
    # Pad frame origin: skin node with the largest z_pad . p (first tag wins on ties,
    # like the C++ loader iterating sorted skin nodes with '>').
    _, _, ez = m.axes()
    best = -float("inf")
    for n in m.skin_nodes():
        h = dot(ez, m.nodes[n])
        if h > best:
            best, m.origin = h, m.nodes[n]
    return m


def plot_python():
    """An interpreter that has matplotlib (tools/plot_press.py): this one, else /usr/bin/python3."""
    import subprocess
    import sys
    for exe in (sys.executable, "/usr/bin/python3"):
        if exe and os.path.exists(exe) and subprocess.call(
                [exe, "-c", "import matplotlib"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) == 0:
            return exe
    return sys.executable


def vertex_area_shares(triangles, pos):
    """One third of each adjacent triangle's area per node (rest geometry)."""
    area = {}
    for a, b, c in triangles:
        n = cross(sub(pos[b], pos[a]), sub(pos[c], pos[a]))
        s = 0.5 * math.sqrt(dot(n, n)) / 3.0
        for v in (a, b, c):
            area[v] = area.get(v, 0.0) + s
    return area
