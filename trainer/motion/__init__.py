"""Motion clips in numpy: the clip type and manifests, canonicalisation, labels, the numpy FK environment, synthesis. No bpy."""
