#!/usr/bin/env python3
"""test_openapi_contract.py - openapi.yaml says what the validator says: the report's
four examples match the JobSpec schema, the bad specs of test_service_errors.py that a
JSON Schema can express are rejected by it, and the process descriptions served at
/processes/pack2d and /processes/pack3d (server/process-*.json) repeat the same input
schemas (Inputs, Inputs3D).
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

    for process_id, schema in (("pack2d", "Inputs"), ("pack3d", "Inputs3D")):
        check_process(c, api, process_id, schema)
    # a spec is one process's: the 3D inputs match JobSpec, a 2D domain with a depth does not
    box = {"inputs": {"domain": {"width": 10, "height": 10, "depth": 10},
                      "distribution": {"kind": "constant", "radius": 1}, "seed": 2}}
    c.check(not api.validate(spec_schema, box), "JobSpec refuses a pack3d spec")
    box["inputs"]["balance"] = {}
    c.check(api.validate(spec_schema, box), "JobSpec accepts a pack3d spec with a balance")


def check_process(c, api, process_id, schema):
    """The process description served at /processes/ID repeats the inputs' schema."""
    with open(os.path.join(gpd.ROOT, "server", f"process-{process_id}.json")) as f:
        process = json.load(f)
    errors = api.validate(api.schema("Process"), process)
    c.check(not errors, f"process-{process_id}.json is not a Process: {errors[:2]}")
    c.check(process["id"] == process_id, f"process-{process_id}.json has id {process['id']}")
    inputs = resolve(api, api.schema(schema))
    c.check(set(process["inputs"]) == set(inputs["properties"]), f"{process_id} inputs differ from {schema}")
    for name, desc in process["inputs"].items():
        ours = resolve(api, desc["schema"])
        theirs = inputs["properties"].get(name)
        c.check(ours == theirs, f"{process_id} input {name}: process description {ours} vs openapi.yaml {theirs}")
        required = name in inputs["required"]
        c.check(desc["minOccurs"] == (1 if required else 0), f"{process_id} input {name}: minOccurs")

if __name__ == "__main__":
    gpd.main(test)
