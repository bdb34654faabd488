"""tapespring: nonlinear shell simulation and experimental analysis of tape springs."""
