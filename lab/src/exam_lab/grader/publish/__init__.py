"""What the teacher reads: grade.md/json, grades.csv, the class page, flight plots, Moodle's
worksheet, Gradescope's results.json, progress on the terminal. Reads records only."""
