"""Systems of lines meeting at points and bodies (docs/method.md §13): each line of a
system as a component held at its two ends (held_line.py), whose end forces and their
exact linearisation the coupled equilibrium of the points and bodies reads."""
