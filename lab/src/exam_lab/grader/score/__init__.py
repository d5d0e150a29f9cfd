"""Pure: the sheets' items and the rubric that turns measurements into points and a status."""
