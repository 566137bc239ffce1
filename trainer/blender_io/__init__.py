"""Blender at the edges of the trainer: the rig session, the bpy FK environment, clip import, baking and FBX, procedural IK."""
