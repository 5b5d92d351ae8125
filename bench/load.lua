-- load.lua - wrk script for bench/load.sh: one endpoint per wrk process, chosen by
-- GP_LOAD_MODE (submit: POST the spec in GP_SPEC; poll: GET /jobs/{id}; fetch: GET
-- /jobs/{id}/results?f=csv, ids taken at random from the file GP_IDS), with the key in
-- GP_KEY. Counts the answers by status and prints them as "status CODE COUNT" lines;
-- the jobIDs of the 201s go to the file GP_ACCEPTED, one a line.
local mode = os.getenv("GP_LOAD_MODE")
local key = os.getenv("GP_KEY")
local ids = {}
for line in io.lines(os.getenv("GP_IDS")) do
  ids[#ids + 1] = line
end

local threads = {}
function setup(thread)
  threads[#threads + 1] = thread
end

function init(args)
  statuses = {}
  accepted = {}
  math.randomseed(os.time() + #threads)
  wrk.headers["Authorization"] = "Bearer " .. key
  if mode == "submit" then
    local f = assert(io.open(os.getenv("GP_SPEC"), "rb"))
    wrk.method = "POST"
    wrk.body = f:read("*a")
    wrk.headers["Content-Type"] = "application/json"
    f:close()
  end
end

function request()
  if mode == "submit" then
    return wrk.format(nil, "/processes/pack2d/execution")
  end
  local id = ids[math.random(#ids)]
  if mode == "poll" then
    return wrk.format(nil, "/jobs/" .. id)
  end
  return wrk.format(nil, "/jobs/" .. id .. "/results?f=csv")
end

function response(status, headers, body)
  statuses[status] = (statuses[status] or 0) + 1
  if status == 201 then
    accepted[#accepted + 1] = string.match(body, '"jobID":"([^"]+)"')
  end
end

function done(summary, latency, requests)
  local total = {}
  local out = assert(io.open(os.getenv("GP_ACCEPTED"), "w"))
  for _, thread in ipairs(threads) do
    for code, n in pairs(thread:get("statuses")) do
      total[code] = (total[code] or 0) + n
    end
    for _, id in ipairs(thread:get("accepted")) do
      out:write(id, "\n")
    end
  end
  out:close()
  for code, n in pairs(total) do
    io.write(string.format("status %d %d\n", code, n))
  end
end
