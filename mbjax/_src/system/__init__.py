"""The systems every integrator and driver sees (Anderson 1993 §2, Borri 1990 §2): the abstract
system, the open tree, the applied forces every driven system shares, the forward-dynamics
strategies, invariants and statuses."""
