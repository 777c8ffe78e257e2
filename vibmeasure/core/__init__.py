"""The data model, units and errors."""
