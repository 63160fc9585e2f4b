"""Exports assets/gltf-corpus/blender-5.glb with Blender's own glTF exporter: a trunk and a
crown of alpha-clipped leaf cards (the corpus's leaf image), a wind animation on the crown, as
a Blender user would make and export a tree. Run with Blender's Python module from PyPI:

    python3 -m venv /tmp/bpyenv && /tmp/bpyenv/bin/pip install bpy
    /tmp/bpyenv/bin/python scripts/blender_corpus.py

(scripts/make_gltf_corpus.py writes the leaf image first.) Nothing third-party goes into the
file but what Blender's exporter writes about itself (asset.generator).
"""

import math
import os

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "..", "assets", "gltf-corpus")

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene

# The trunk: a six-sided cylinder 2.2 m tall, bark-brown.
bpy.ops.mesh.primitive_cylinder_add(vertices=6, radius=0.15, depth=2.2, location=(0, 0, 1.1))
trunk = bpy.context.object
trunk.name = "Trunk"
bark = bpy.data.materials.new("Bark")
bark.use_nodes = True
bark.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.18, 0.1, 0.05, 1)
trunk.data.materials.append(bark)

# The crown: 40 leaf cards on a golden-angle spiral, joined into one mesh.
cards = []
for k in range(40):
    t = (k + 0.5) / 40
    el = math.asin(1 - 2 * t)
    az = k * 2.399963
    r = 1.2 * (0.55 + 0.45 * ((k * 37) % 11) / 10)
    loc = (r * math.cos(el) * math.cos(az), r * math.cos(el) * math.sin(az), 2.5 + r * math.sin(el))
    bpy.ops.mesh.primitive_plane_add(size=0.35, location=loc)
    c = bpy.context.object
    # Face outwards from the crown's centre.
    c.rotation_euler = (math.pi / 2 - el, 0, az + math.pi / 2)
    cards.append(c)
bpy.ops.object.select_all(action="DESELECT")
for c in cards:
    c.select_set(True)
bpy.context.view_layer.objects.active = cards[0]
bpy.ops.object.join()
crown = bpy.context.object
crown.name = "Crown"

leaf = bpy.data.materials.new("Leaf")
leaf.use_nodes = True
nodes, links = leaf.node_tree.nodes, leaf.node_tree.links
bsdf = nodes["Principled BSDF"]
tex = nodes.new("ShaderNodeTexImage")
tex.image = bpy.data.images.load(os.path.join(OUT, "interleaved-leaf.png"))
clip = nodes.new("ShaderNodeMath")
clip.operation = "ROUND"  # the exporter's sign for alpha clipping (MASK, cutoff 0.5)
links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
links.new(tex.outputs["Alpha"], clip.inputs[0])
links.new(clip.outputs[0], bsdf.inputs["Alpha"])
leaf.use_backface_culling = False
crown.data.materials.append(leaf)

# Wind: the crown sways about its base over two seconds.
crown.parent = trunk
crown.location = (0, 0, 0)
for frame, angle in ((1, 0.0), (25, 0.04), (49, 0.0)):
    crown.rotation_euler = (angle, 0, 0)
    crown.keyframe_insert("rotation_euler", frame=frame)

bpy.ops.export_scene.gltf(filepath=os.path.join(OUT, "blender-5.glb"), export_format="GLB")
print("wrote", os.path.join(OUT, "blender-5.glb"))
