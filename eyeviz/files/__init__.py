"""Safe file handling shared by every writer and reader (atomic outputs)."""
