"""A griffe extension for the API reference (mkdocs.yml): equinox modules' constructors.

An `equinox.Module` without an `__init__` of its own gets a dataclass `__init__` from its fields
when its class is created, which griffe's static analysis does not see: such a class would render
with no signature, and its Args table with no types and every default "required". This gives each
one the `__init__` that equinox generated (the live signature: names, order, keyword-only markers,
defaults), typed with the fields' annotations from the source.
"""

import importlib
import inspect

import griffe


def _classes(obj):
    for member in obj.members.values():
        if member.is_alias:
            continue
        if member.is_class:
            yield member
            yield from _classes(member)
        elif member.is_module:
            yield from _classes(member)


def _annotation(cls, name: str):
    """The annotation of field `name` on cls or the first base that declares it."""
    try:
        mro = [cls, *cls.mro()]
    except ValueError:
        mro = [cls]
    for klass in mro:
        member = klass.members.get(name)
        if member is not None and not member.is_alias and member.is_attribute:
            return member.annotation
    return None


_KINDS = {
    inspect.Parameter.POSITIONAL_ONLY: griffe.ParameterKind.positional_only,
    inspect.Parameter.POSITIONAL_OR_KEYWORD: griffe.ParameterKind.positional_or_keyword,
    inspect.Parameter.VAR_POSITIONAL: griffe.ParameterKind.var_positional,
    inspect.Parameter.KEYWORD_ONLY: griffe.ParameterKind.keyword_only,
    inspect.Parameter.VAR_KEYWORD: griffe.ParameterKind.var_keyword,
}


class EquinoxInit(griffe.Extension):
    """Adds the generated `__init__` to equinox modules that do not write their own."""

    def on_package(self, *, pkg: griffe.Module, **kwargs) -> None:
        import equinox as eqx

        for cls in _classes(pkg):
            if not cls.parent.is_module or "__init__" in cls.all_members:
                continue
            try:
                live = getattr(importlib.import_module(cls.parent.path), cls.name)
            except (ImportError, AttributeError):
                continue
            if not (isinstance(live, type) and issubclass(live, eqx.Module)):
                continue
            try:
                signature = inspect.signature(live.__init__)
            except (TypeError, ValueError):
                continue
            parameters = [griffe.Parameter("self", kind=griffe.ParameterKind.positional_or_keyword)]
            for p in list(signature.parameters.values())[1:]:
                default = None if p.default is inspect.Parameter.empty else repr(p.default)
                parameters.append(griffe.Parameter(p.name, annotation=_annotation(cls, p.name),
                                                   kind=_KINDS[p.kind], default=default))
            init = griffe.Function("__init__", lineno=0, endlineno=0, parent=cls,
                                   parameters=griffe.Parameters(*parameters), returns="None")
            cls.set_member("__init__", init)
