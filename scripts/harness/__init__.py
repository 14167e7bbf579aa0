"""Speed-versus-accuracy harness: scene library, Cycles ground truth, metrics, method list, report."""
