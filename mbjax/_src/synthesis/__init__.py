"""The Carpal Wrist's trajectory synthesis (Canfield 1997 §6): the minimum-jerk baseline, gradient
synthesis of torque splines, a neural controller, batches and grids of wrists."""
