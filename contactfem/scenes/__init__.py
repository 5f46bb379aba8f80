"""Scenes: each module composes bodies, obstacles, laws and loads into one of the
paper's examples (or a verification problem) and declares its parameters."""
