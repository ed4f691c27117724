"""What every time integrator shares: step-size control, contact events inside a step,
peaks, dense output, copies."""
