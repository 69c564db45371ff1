"""Laws and shapes (layer 2, docs/architecture.md).

The pair and wall force laws, materials and their Thiele parameters, the hypothesis knobs, and the
outlines of devices with their ports.
"""
