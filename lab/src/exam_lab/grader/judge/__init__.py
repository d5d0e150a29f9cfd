"""The judge: one submission's session, its masters and the probe that measures the student's nodes.
Never root: it runs as a judge uid of its own, outside the student's box, and never reads the
student's files."""
