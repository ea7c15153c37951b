"""Data layer: flight-test records (``record-format.md``), trim, pilot input shapes."""
from .record import Record, Trim, find_trim, model_inputs, read_record, write_record

__all__ = ["Record", "Trim", "find_trim", "model_inputs", "read_record", "write_record"]
