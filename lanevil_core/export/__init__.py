"""Files out: image encoders, and a case's frames, labels and 3D scene."""
