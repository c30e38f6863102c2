-- returns.lua KIND -- a script whose result is its exit status: "3" returns
-- 3; "string", "float" and "big" (256, which a shell would wrap to 0) return
-- what is no exit status, which must fail (exit 1), never pass as success.
local results = { ["3"] = 3, string = "done", float = 0.0, big = 256 }
return results[arg[1]]
