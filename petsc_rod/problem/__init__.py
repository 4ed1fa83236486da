"""The problem apart from its solver: RodProblem (problem.py), its state (state.py,
node_values.py), the penalty's scale and split (penalty.py), and the terms a scene
needs (build.py)."""
