"""Blender at the trainer's edges: the rig session, the bpy FK environment, clip import, baking and FBX,
procedural IK."""
