"""The agent and Algorithm 1 in torch (no bpy): configs, models, losses, buffer, training, checkpoints, agent files."""
