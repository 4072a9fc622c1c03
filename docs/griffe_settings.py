"""Griffe extension (mkdocs.yml, mkdocstrings' ``extensions``): the API pages show each config setting's help.

A setting is documented by its ``setting(default, help, check)`` call (``pamdp.algos.settings``), the text
``pamdp train --help`` and docs/algorithms.md print, not by a docstring under the field, so the API reference
would list no settings. This extension imports each dataclass the pages document and gives every field that
the class itself declares its ``help`` as the docstring.
"""

from __future__ import annotations

import dataclasses

import griffe


class SettingDocs(griffe.Extension):
    def on_class_members(self, *, cls: griffe.Class, **kwargs) -> None:
        runtime = griffe.dynamic_import(cls.path)  # an import error fails the build: the docs need pamdp installed
        if not dataclasses.is_dataclass(runtime):
            return
        for field in dataclasses.fields(runtime):
            member = cls.members.get(field.name)
            if "help" in field.metadata and member is not None and not member.is_alias and member.docstring is None:
                member.docstring = griffe.Docstring(field.metadata["help"], parent=member)
