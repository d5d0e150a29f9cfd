"""Runs as a box's uid, never root, on the student's bytes: intake, inspection, launch and YAML
analysis, the source scan, PDF facts, similarity. What it finds leaves as one capped JSON record."""
