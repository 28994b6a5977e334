"""Lane ground truth (TuSimple records, CULane lines) and lanes drawn on images."""
