"""Motion clips in numpy (no bpy): the clip type and manifests, canonicalisation, labels, FK, synthesis."""
