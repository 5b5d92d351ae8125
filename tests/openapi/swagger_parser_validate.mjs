// swagger_parser_validate.mjs - openapi.yaml through @apidevtools/swagger-parser: parsed,
// every $ref resolved, validated against the OpenAPI 3.1 schema and its own rules (unique
// operationIds, path parameters declared, ...). Prints what it found; exit 1 when invalid.
// Usage: node swagger_parser_validate.mjs openapi.yaml
import SwaggerParser from "@apidevtools/swagger-parser";

const path = process.argv[2];
try {
  const api = await SwaggerParser.validate(path);
  const operations = Object.values(api.paths).flatMap((item) =>
    Object.keys(item).filter((k) => ["get", "put", "post", "delete", "patch", "head", "options"].includes(k)));
  console.log(`swagger-parser: ${path} is valid OpenAPI ${api.openapi} ` +
              `(${api.info.title} ${api.info.version}, license ${api.info.license.identifier}): ` +
              `${Object.keys(api.paths).length} paths, ${operations.length} operations, ` +
              `${Object.keys(api.components.schemas).length} schemas`);
} catch (e) {
  console.error(`swagger-parser: ${path} is not valid: ${e.message}`);
  process.exit(1);
}
