"""Checks a stage with every validator of Pixar's USD (`UsdValidation`, which replaced `UsdUtils.ComplianceChecker`
in the usd-core the tests pin: the stage's metadata, schema types and attribute types, UsdSkel bindings, and a
`.usdz`'s package rules) and prints what they find as JSON: each error's validator, type and message.

Usage: python compliance.py FILE
"""
import json
import sys

from pxr import Usd, UsdValidation


def main(path):
    registry = UsdValidation.ValidationRegistry()
    context = UsdValidation.ValidationContext(registry.GetOrLoadAllValidators())
    stage = Usd.Stage.Open(path)
    errors = context.Validate(stage)
    print(json.dumps({
        "validators": len(registry.GetAllValidatorMetadata()),
        "errors": [{"validator": str(e.GetValidator().GetMetadata().name) if e.GetValidator() else "",
                    "type": str(e.GetType()), "message": e.GetMessage()} for e in errors],
    }))


if __name__ == "__main__":
    main(sys.argv[1])
