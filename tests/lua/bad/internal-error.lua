-- internal-error.lua -- a helper of the lab fails inside itself (json.decode
-- given no text): the lab's own error, so it keeps its traceback.
local json = require "shadowlab.json"
return json.decode(nil)
