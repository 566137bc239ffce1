"""RLAnimate for Blender: trained RL agents that bake pointing and waving gestures onto Mixamo-named rigs.

`core/` is numpy only and imports without Blender (the trainer uses it too); `blender/` is the
thin Blender edge. register()/unregister() import the Blender edge only when called.
"""


def register():
    from .blender import registration
    registration.register()


def unregister():
    from .blender import registration
    registration.unregister()


class glTF2ImportUserExtension:  # noqa: N801 (the name Blender's glTF importer looks for on enabled add-ons)
    """Blender's glTF importer calls this on every import: an armature imported from a VRM file keeps
    that file's path, so its own humanoid map names its bones (blender/vrm_map.py)."""

    def gather_import_scene_after_nodes_hook(self, gltf_scene, blender_scene, gltf):
        from .blender import vrm_map
        vrm_map.remember_vrm_file(gltf)
