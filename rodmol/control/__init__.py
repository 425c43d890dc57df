"""Control: questions a controller asks of the model (inverse statics)."""

from .inverse_statics import StaticFit, inverse_statics, inverse_statics_path

__all__ = ["StaticFit", "inverse_statics", "inverse_statics_path"]
