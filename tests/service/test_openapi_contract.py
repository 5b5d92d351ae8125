#!/usr/bin/env python3
"""test_openapi_contract.py - openapi.yaml says what the validator says: the report's
four examples match the JobSpec schema, the bad specs of test_service_errors.py that a
JSON Schema can express are rejected by it, and the process description served at
/processes/pack2d (server/process-pack2d.json) repeats the same input schemas.
(The document itself is checked against the OpenAPI 3.1 schema by test_openapi_valid.)"""

import json
import os

import gpd
import test_service_errors

# Rules that span fields, which JSON Schema cannot state: the validator checks them.
NOT_EXPRESSIBLE = {
    "not JSON at all", "an empty body", "duplicate keys",
    "probabilities not summing to 1", "overlapping bins", "a bin with max below min",
    "a uniform law with max below min", "a grain larger than the domain", "more disks than --max-disks",
}


def resolve(api, node):
    """node with every $ref replaced by what it points to."""
    if isinstance(node, dict):
        if "$ref" in node:
            return resolve(api, api.resolver.resolve(node["$ref"])[1])
        return {k: resolve(api, v) for k, v in node.items() if k != "description"}
    if isinstance(node, list):
        return [resolve(api, v) for v in node]
    return node


def test(c):
    api = gpd.OpenAPI()
    spec_schema = api.schema("JobSpec")
    for name in ["fixed", "variable", "iron", "bagi"]:
        example = gpd.load_example(name)
        errors = api.validate(spec_schema, example)
        c.check(not errors, f"examples/{name}.json does not match JobSpec: {errors[:2]}")
        errors = api.validate(spec_schema, example["inputs"])
        c.check(not errors, f"bare inputs of {name} do not match JobSpec: {errors[:2]}")
    rejected = 0
    for what, body, status, *_ in test_service_errors.SPEC_CASES:
        if what in NOT_EXPRESSIBLE:
            continue
        instance = json.loads(body) if isinstance(body, bytes) else body
        c.check(api.validate(spec_schema, instance), f"JobSpec accepts {what}")
        rejected += 1
    c.check(rejected >= 15, f"only {rejected} bad specs checked against the schema")

    with open(os.path.join(gpd.ROOT, "server", "process-pack2d.json")) as f:
        process = json.load(f)
    errors = api.validate(api.schema("Process"), process)
    c.check(not errors, f"process-pack2d.json is not a Process: {errors[:2]}")
    inputs = resolve(api, api.schema("Inputs"))
    c.check(set(process["inputs"]) == set(inputs["properties"]), "process inputs differ from Inputs")
    for name, desc in process["inputs"].items():
        ours = resolve(api, desc["schema"])
        theirs = inputs["properties"].get(name)
        c.check(ours == theirs, f"input {name}: process description {ours} vs openapi.yaml {theirs}")
        required = name in inputs["required"]
        c.check(desc["minOccurs"] == (1 if required else 0), f"input {name}: minOccurs")


if __name__ == "__main__":
    gpd.main(test)
