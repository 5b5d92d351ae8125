-- submit.lua - wrk script for bench/service.sh: POSTs the job spec in $GP_SPEC.
local f = assert(io.open(os.getenv("GP_SPEC"), "rb"))
wrk.method = "POST"
wrk.body = f:read("*a")
wrk.headers["Content-Type"] = "application/json"
f:close()
