"""Objects: the catalogue, the random training family, user meshes and resting states."""

from affordplan.objects.model import ObjectModel, catalogue, load_object, random_object
from affordplan.objects.resting import RestingState

__all__ = ["ObjectModel", "RestingState", "catalogue", "load_object", "random_object"]
