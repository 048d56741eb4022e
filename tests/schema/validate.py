#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Validate one JSON document on standard input against a JSON Schema.

usage: validate.py SCHEMA.json < document.json

Standard library only (no pip package): the input must be UTF-8, one JSON
value with no NaN, Infinity or duplicate keys, and it must satisfy the
schema.  The subset of JSON Schema (draft 2020-12) implemented is what
doc/schema/ uses: type, enum, const, properties, required,
additionalProperties, items, minItems, maxItems, minimum, maximum,
minLength, oneOf, anyOf, $ref (to another file in the same directory, to
a JSON pointer, or both) and $defs; any other keyword is an error, so a
misspelt one cannot pass silently.  Exit status 0 when valid, 1 with the
reasons on standard error.
"""
import json
import os
import sys

KNOWN = {"$schema", "$id", "title", "description", "$defs", "$ref", "type", "enum", "const",
         "properties", "required", "additionalProperties", "items", "minItems", "maxItems",
         "minimum", "maximum", "minLength", "oneOf", "anyOf"}


def no_duplicates(pairs):
    keys = [k for k, _ in pairs]
    if len(keys) != len(set(keys)):
        raise ValueError("duplicate key in an object: %r" % keys)
    return dict(pairs)


def no_constant(name):
    raise ValueError("%s is not JSON" % name)


class Validator:
    def __init__(self, path):
        self.dir = os.path.dirname(os.path.abspath(path))
        self.files = {}
        self.root_name = os.path.basename(path)

    def load(self, name):
        if name not in self.files:
            with open(os.path.join(self.dir, name), encoding="utf-8") as f:
                self.files[name] = json.load(f)
        return self.files[name]

    def resolve(self, ref, base):
        name, _, pointer = ref.partition("#")
        name = name or base
        node = self.load(name)
        for part in [p for p in pointer.split("/") if p]:
            node = node[int(part)] if isinstance(node, list) else node[part]
        return node, name

    def type_ok(self, value, t):
        if t == "null":
            return value is None
        if t == "boolean":
            return isinstance(value, bool)
        if t == "integer":
            return isinstance(value, int) and not isinstance(value, bool)
        if t == "number":
            return isinstance(value, (int, float)) and not isinstance(value, bool)
        if t == "string":
            return isinstance(value, str)
        if t == "array":
            return isinstance(value, list)
        if t == "object":
            return isinstance(value, dict)
        raise ValueError("unknown type %r" % t)

    def check(self, value, schema, where, base, errors):
        if schema is True:
            return
        if schema is False:
            errors.append("%s: not allowed" % where)
            return
        unknown = set(schema) - KNOWN
        if unknown:
            raise ValueError("schema keyword(s) not implemented: %s" % sorted(unknown))
        if "$ref" in schema:
            target, name = self.resolve(schema["$ref"], base)
            self.check(value, target, where, name, errors)
        if "type" in schema:
            types = schema["type"] if isinstance(schema["type"], list) else [schema["type"]]
            if not any(self.type_ok(value, t) for t in types):
                errors.append("%s: %r is not of type %s" % (where, value, "/".join(types)))
                return
        if "enum" in schema and value not in schema["enum"]:
            errors.append("%s: %r is not one of %r" % (where, value, schema["enum"]))
        if "const" in schema and value != schema["const"]:
            errors.append("%s: %r is not %r" % (where, value, schema["const"]))
        numeric = isinstance(value, (int, float)) and not isinstance(value, bool)
        if numeric and "minimum" in schema and value < schema["minimum"]:
            errors.append("%s: %r < %r" % (where, value, schema["minimum"]))
        if numeric and "maximum" in schema and value > schema["maximum"]:
            errors.append("%s: %r > %r" % (where, value, schema["maximum"]))
        if isinstance(value, str) and len(value) < schema.get("minLength", 0):
            errors.append("%s: string shorter than %d" % (where, schema["minLength"]))
        if isinstance(value, dict):
            props = schema.get("properties", {})
            for key in schema.get("required", []):
                if key not in value:
                    errors.append("%s: required property %r missing" % (where, key))
            extra = schema.get("additionalProperties", True)
            for key, item in value.items():
                if key in props:
                    self.check(item, props[key], "%s.%s" % (where, key), base, errors)
                else:
                    self.check(item, extra, "%s.%s" % (where, key), base, errors)
        if isinstance(value, list):
            if len(value) < schema.get("minItems", 0):
                errors.append("%s: fewer than %d items" % (where, schema["minItems"]))
            if "maxItems" in schema and len(value) > schema["maxItems"]:
                errors.append("%s: more than %d items" % (where, schema["maxItems"]))
            if "items" in schema:
                for i, item in enumerate(value):
                    self.check(item, schema["items"], "%s[%d]" % (where, i), base, errors)
        for key in ("oneOf", "anyOf"):
            if key in schema:
                passing = 0
                for option in schema[key]:
                    sub = []
                    self.check(value, option, where, base, sub)
                    passing += not sub
                if (key == "oneOf" and passing != 1) or (key == "anyOf" and passing == 0):
                    errors.append("%s: %d of the %s alternatives match" % (where, passing, key))


def main():
    if len(sys.argv) != 2:
        sys.stderr.write(__doc__)
        return 2
    raw = sys.stdin.buffer.read()
    try:
        text = raw.decode("utf-8")
        doc = json.loads(text, object_pairs_hook=no_duplicates, parse_constant=no_constant)
    except (UnicodeDecodeError, ValueError) as e:
        sys.stderr.write("not valid JSON: %s\n" % e)
        return 1
    v = Validator(sys.argv[1])
    errors = []
    v.check(doc, v.load(v.root_name), "$", v.root_name, errors)
    for e in errors:
        sys.stderr.write(e + "\n")
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
