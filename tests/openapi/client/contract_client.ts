// contract_client.ts - a client of grainpackd made from openapi.yaml alone: the types in
// ./api.js are generated from the document by openapi-typescript when the test runs, tsc
// type-checks this file against them (strict), and node runs it against the real daemon.
// A request or an answer that the document describes wrongly fails here, at compile time
// or at run time. Usage: node contract_client.js BASE_URL MAX_WAIT, MAX_WAIT being the
// document's maximum for ?wait= (the test, test_openapi_client.py, reads it there).
import createClient from "openapi-fetch";
import type { components, paths } from "./api.js";

type ExecuteRequest = components["schemas"]["ExecuteRequest"];
type Inputs = components["schemas"]["Inputs"];

let failures = 0;
function check(cond: boolean, what: string): void {
  if (!cond) {
    failures++;
    console.error(`FAIL contract client: ${what}`);
  }
}

// What the types refuse, at compile time: tsc fails if these are accepted.
// @ts-expect-error a width is a number
const badWidth: Inputs = { domain: { width: "30", height: 30 }, distribution: { kind: "constant", radius: 1 } };
// @ts-expect-error no such law
const badLaw: Inputs = { domain: { width: 30, height: 30 }, distribution: { kind: "normal", radius: 1 } };
void badWidth;
void badLaw;

// The report's variable case, smaller, balanced, with Laguerre cells.
const spec: ExecuteRequest = {
  inputs: {
    domain: { width: 20, height: 20 },
    distribution: {
      kind: "histogram",
      bins: [{ min: 0.2, max: 0.4, p: 0.3 }, { min: 0.4, max: 0.6, p: 0.2 }, { min: 0.6, max: 0.9, p: 0.5 }],
    },
    joint: { law: "constant", value: 0.1 },
    balance: { method: "relocation" },
    laguerre: { shrink: "offset" },
    seed: 3,
  },
};
// Valid for the types, refused by the validator (a rule a schema cannot state): 422.
const unbalanced: ExecuteRequest = {
  inputs: {
    domain: { width: 20, height: 20 },
    distribution: { kind: "histogram", bins: [{ min: 0.2, max: 0.4, p: 0.3 }, { min: 0.4, max: 0.6, p: 0.3 }] },
  },
};

const client = createClient<paths>({ baseUrl: process.argv[2] });
const maxWait = Number(process.argv[3]);
const pack2d = { path: { processId: "pack2d" } };

// submit: 201, a StatusInfo and its Location
const submitted = await client.POST("/processes/{processId}/execution", { params: pack2d, body: spec });
check(submitted.response.status === 201 && submitted.data !== undefined, `submit: ${submitted.response.status}`);
const jobId = submitted.data?.jobID ?? "";
check(submitted.response.headers.get("location") === `/jobs/${jobId}`, "submit: Location is not /jobs/{jobID}");

// wait with the long-poll, as long as the document allows
let status = submitted.data?.status;
for (let round = 0; round < 20 && (status === "accepted" || status === "running"); round++) {
  const polled = await client.GET("/jobs/{jobId}", { params: { path: { jobId }, query: { wait: maxWait } } });
  check(polled.data !== undefined, `wait: ${polled.response.status}`);
  status = polled.data?.status;
}
check(status === "successful", `the job ended ${status}`);
// one second more than the document allows is refused by a daemon with default options
const tooLong = await client.GET("/jobs/{jobId}", { params: { path: { jobId }, query: { wait: maxWait + 1 } } });
check(tooLong.response.status === 400 && tooLong.error?.type === "urn:grainpack:problem:bad-parameter",
      `wait=${maxWait + 1}: ${tooLong.response.status} ${tooLong.error?.type}`);

// the results, as JSON (typed) and as CSV (text)
// (the operation has four media types: the JSON one is the object, the others text; the
// object is a pack2d Result, with disks, or a pack3d one, with spheres)
const result = await client.GET("/jobs/{jobId}/results", { params: { path: { jobId }, query: { f: "json" } } });
const json = typeof result.data === "object" && "disks" in result.data ? result.data : undefined;
const disks = json?.disks ?? [];
const count = json?.statistics.count ?? -1;
check(result.response.status === 200 && disks.length === count && count > 100, `results: ${count} disks`);
check(json?.cells?.length === count, `results: ${json?.cells?.length} cells for ${count} disks`);
check(disks.every((d) => d.R >= d.r && d.x >= d.R - 1e-9 && d.x <= 20 - d.R + 1e-9), "a disk outside the domain");
const csv = await client.GET("/jobs/{jobId}/results", {
  params: { path: { jobId }, query: { f: "csv" } }, parseAs: "text",
});
const lines = (csv.data ?? "").trim().split("\n");
check(lines[0] === "x,y,r,R" && lines.length === count + 1, `csv: ${lines.length} lines`);

const stats = await client.GET("/jobs/{jobId}/statistics", { params: { path: { jobId } } });
check((stats.data?.timings.length ?? 0) > 0 && stats.data?.count === count, "statistics");
const list = await client.GET("/jobs", { params: { query: { status: "successful", limit: 5 } } });
check(list.data?.jobs.some((j) => j.jobID === jobId) === true, "the job is not in /jobs?status=successful");

// errors: an invalid spec (422, with the field's pointer), an unknown job (404)
const invalid = await client.POST("/processes/{processId}/execution", { params: pack2d, body: unbalanced });
const problem = invalid.error;
check(invalid.response.status === 422 && problem !== undefined && "pointer" in problem &&
      problem.pointer === "/inputs/distribution/bins",
      `invalid spec: ${invalid.response.status} ${JSON.stringify(problem)}`);
const missing = await client.GET("/jobs/{jobId}", { params: { path: { jobId: "no-such-job" } } });
check(missing.response.status === 404 && missing.error?.status === 404, `unknown job: ${missing.response.status}`);

// a finished job is deleted; then it is gone
const deleted = await client.DELETE("/jobs/{jobId}", { params: { path: { jobId } } });
check(deleted.data?.status === "dismissed", `delete: ${deleted.response.status}`);
const gone = await client.GET("/jobs/{jobId}", { params: { path: { jobId } } });
check(gone.response.status === 404, `after delete: ${gone.response.status}`);

if (failures > 0) {
  console.error(`${failures} check(s) failed`);
  process.exit(1);
}
console.log(`contract client: job ${jobId} ${status}, ${count} disks and cells, CSV, statistics, ` +
            `list, wait=${maxWait} accepted and ${maxWait + 1} -> 400, invalid spec -> 422 at ${problem && "pointer" in problem ? problem.pointer : "?"}, ` +
            `unknown job -> 404, delete -> gone`);
