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
