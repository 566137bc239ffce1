"""The agent and Algorithm 1 in torch: configs, models, losses, buffer, training loop, checkpoints, agent files. No bpy."""
