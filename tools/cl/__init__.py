"""The ./course command's modules (docs/DESIGN.md §1): tools/course.py dispatches to them."""
