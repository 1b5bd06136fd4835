"""System-level crash scenes with the contact element between moving bodies,
solved monolithically in scipy as the references of their co-simulations:
headform (a pedestrian headform on a bonnet over a hard point) and bumper (a
vehicle's bumper against a barrier at low speed); chain is their solver,
parameters their published and assumed values."""
