"""The report: figures and the PDF, built from result files only (no solver is run here)."""
