"""Reports: the robustness tables and plot, detectors side by side, intervals, the realism table, the
illusion contact sheet."""
