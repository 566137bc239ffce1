"""The headless trainer: Blender as the forward-kinematics environment, torch for the agent."""
