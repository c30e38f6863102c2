-- records.lua -- a sweep's results on disk: JSON Lines (a header line, then
-- one row per configuration) and the same rows as CSV. Each row is appended
-- with a single write, then flushed and fsynced, so a sweep killed at any
-- point (Ctrl-C, kill -9, power loss) keeps every finished row; a half-written
-- last row (no newline) is detected on reading and dropped. The CSV is
-- rewritten from the JSON Lines whenever a results file is reopened.
local sl = package.loaded.shadowlab or require "shadowlab"
local json = require "shadowlab.json"

local records = {}

---------------------------------------------------------------- reading

-- header, rows, dropped (half-written rows dropped) of a results file; nil
-- when the file does not exist. A malformed complete line is an error naming
-- the file and line (an append-only writer cannot leave one mid-file).
function records.read(path)
  local f = io.open(path, "rb")
  if not f then return nil end
  local text = f:read("a")
  f:close()
  local lines, dropped, pos = {}, 0, 1
  while pos <= #text do
    local nl = text:find("\n", pos, true)
    if not nl then
      dropped = 1
      break
    end
    lines[#lines + 1] = text:sub(pos, nl - 1)
    pos = nl + 1
  end
  if #lines == 0 then
    error(string.format("%s: no header line (an empty or truncated results file)", path), 0)
  end
  local decoded = {}
  for i, line in ipairs(lines) do
    local ok, value = pcall(json.decode, line)
    if not ok or type(value) ~= "table" then
      error(string.format("%s:%d: %s", path, i, ok and "not a JSON object" or value), 0)
    end
    decoded[i] = value
  end
  local header = table.remove(decoded, 1)
  if header.shadowlab_results ~= 1 then
    error(string.format("%s:1: not a shadowlab results file (no shadowlab_results header)", path), 0)
  end
  for i, row in ipairs(decoded) do
    if type(row.key) ~= "string" then error(string.format("%s:%d: row without a key", path, i + 1), 0) end
  end
  return header, decoded, dropped
end

---------------------------------------------------------------- CSV

-- Column name -> value of a row. Names "param:NAME" and "scene:KEY" read the
-- technique's parameter and the scene variant's override.
local function metric(region, field)
  return function(r) return r.record and r.record.metrics and r.record.metrics[region] and r.record.metrics[region][field] end
end
local function timing(field)
  return function(r) return r.record and r.record.timings_s and r.record.timings_s[field] end
end
local function record_field(a, b)
  return function(r) return r.record and r.record[a] and r.record[a][b] end
end

-- The record's machine-independent work counters (src/lab/record.c's `work`
-- block, core/counters.h), what reports plot error against beside time:
-- {column name, label with its unit, path into record.work}.
records.work_counters = {
  { "texel_fetches_per_sample", "texel fetches per lit candidate", "per_sample", "texel_fetches" },
  { "rays_per_sample", "rays per lit candidate", "per_sample", "rays" },
  { "frame_texel_fetches", "texel fetches per frame", "frame", "texel_fetches" },
  { "frame_bytes_read", "bytes read per frame (texel fetches x stored texel size)", "frame", "texel_bytes" },
  { "frame_rays", "rays per frame", "frame", "rays" },
  { "frame_triangles", "triangles set up per frame", "frame", "triangles" },
  { "frame_fragments", "texels rasterised per frame", "frame", "fragments" },
  { "frame_bytes_built", "bytes of resources built per frame", "frame", "bytes_built" },
}
local function work(part, field)
  return function(r) return r.record and r.record.work and r.record.work[part] and r.record.work[part][field] end
end

records.standard_columns = {
  { "index", function(r) return r.index end },
  { "key", function(r) return r.key end },
  { "status", function(r) return r.status end },
  { "scene", function(r) return r.variant and r.variant.scene end },
  { "scene_hash", record_field("scene", "hash") },
  { "variant", function(r) return r.variant and r.variant.label end },
  { "technique", function(r) return r.technique end },
  { "label", function(r) return r.label end },
  { "width", record_field("scene", "width") },
  { "height", record_field("scene", "height") },
  { "frame_s", timing("frame") },
  { "eval_median_s", timing("evaluate_median") },
  { "eval_min_s", timing("evaluate_min") },
  { "prepare_s", timing("prepare") },
  { "technique_build_s", timing("technique_build") },
  { "view_samples_s", timing("view_samples") },
  { "repeats", timing("repeat") },
  { "warmup", timing("warmup") },
  { "resource_cache", function(r) return r.record and r.record.resource_cache end },
  { "reference_origin", record_field("reference", "origin") },
  { "reference_samples", record_field("reference", "samples") },
  { "reference_pattern", record_field("reference", "pattern") },
  { "reference_seed", record_field("reference", "seed") },
  { "reference_measure", record_field("reference", "measure") },
  { "reference_rays", record_field("reference", "rays") },
  { "supersample", record_field("scene", "supersample") },
  { "reference_std_error", record_field("reference", "std_error") },
  { "reference_batches", record_field("reference", "batches") },
  { "noise_rms", metric("all", "noise_rms") },
  { "rmse", metric("all", "rmse") },
  { "rmse_debiased", metric("all", "rmse_debiased") },
  { "resolved", metric("all", "resolved") },
  { "nonfinite", record_field("metrics", "nonfinite") },
  { "mae", metric("all", "mae") },
  { "max_abs", metric("all", "max_abs") },
  { "mean_signed", metric("all", "mean_signed") },
  { "leak", metric("all", "leak_mean") },
  { "dark", metric("all", "dark_mean") },
  { "misclassified", metric("all", "misclassified") },
  { "penumbra_rmse", metric("penumbra", "rmse") },
  { "penumbra_noise_rms", metric("penumbra", "noise_rms") },
  { "penumbra_rmse_debiased", metric("penumbra", "rmse_debiased") },
  { "umbra_rmse", metric("umbra", "rmse") },
  { "lit_rmse", metric("lit", "rmse") },
  { "terminator_rmse", metric("terminator", "rmse") },
  { "false_shadow", record_field("metrics", "false_shadow") },
  { "false_lit", record_field("metrics", "false_lit") },
  { "lit_candidates", record_field("work", "lit_candidates") },
  { "threads", record_field("machine", "threads") },
  { "host", record_field("machine", "host") },
  { "cpu", record_field("machine", "cpu") },
  { "commit", record_field("machine", "commit") },
  { "lua_helpers", function(r) return r.lua_helpers end },
  { "error", function(r) return r.error end },
}

-- The build a row was measured with: commit, CPU model, architecture and
-- worker threads (not the host name: the nodes of one cluster partition are
-- the same machine for timing). nil for a row without a record (a failure).
function records.build_of(row)
  local m = row.record and row.record.machine
  if not m then return nil end
  return { commit = m.commit, lua = row.lua_helpers, cpu = m.cpu, arch = m.arch, threads = m.threads }
end

function records.build_text(b)
  return string.format("commit %s (Lua helpers %s), %s (%s), %s threads", tostring(b.commit), tostring(b.lua),
                       tostring(b.cpu), tostring(b.arch), tostring(b.threads))
end

-- A hash of the lab's Lua helpers (lua/shadowlab/*.lua) as this process finds
-- them: they are read at run time, so the binary's commit stamp cannot see
-- them change after the build. Experiments record it in every row.
local helpers_hash_memo
function records.helpers_hash()
  if helpers_hash_memo then return helpers_hash_memo end
  local dir = sl.root .. "/lua/shadowlab"
  local names, parts = sl.dir(dir) or {}, {}
  table.sort(names)
  for _, name in ipairs(names) do
    if name:match("%.lua$") then
      local f = io.open(dir .. "/" .. name, "rb")
      if f then
        parts[#parts + 1] = name .. "\0" .. f:read("a")
        f:close()
      end
    end
  end
  helpers_hash_memo = sl.hash(table.concat(parts, "\0"))
  return helpers_hash_memo
end

-- The distinct builds of rows, in first-seen order, each with its row count.
function records.builds(rows)
  local list, by_text = {}, {}
  for _, row in ipairs(rows) do
    local b = records.build_of(row)
    if b then
      local t = records.build_text(b)
      if not by_text[t] then
        by_text[t] = { build = b, text = t, rows = 0 }
        list[#list + 1] = by_text[t]
      end
      by_text[t].rows = by_text[t].rows + 1
    end
  end
  return list
end

-- The error metrics a report plots and progress lines print: "REGION.FIELD"
-- (or FIELD, the whole image's) of the record's per-region statistics
-- (src/lab/record.c). Returns region, field; or nil and a message listing
-- the valid names.
records.metric_regions = { "all", "umbra", "penumbra", "lit", "terminator" }
records.metric_fields = { "rmse", "rmse_debiased", "mae", "max_abs", "mean_signed", "leak_mean", "dark_mean",
                          "misclassified", "noise_rms", "noise_mean" }
local function member(list, v)
  for _, x in ipairs(list) do if x == v then return true end end
  return false
end
function records.metric_path(path)
  local region, field = tostring(path):match("^(%w+)%.([%w_]+)$")
  if not region then region, field = "all", tostring(path) end
  if member(records.metric_regions, region) and member(records.metric_fields, field) then return region, field end
  return nil, string.format("unknown error metric '%s'; valid: REGION.FIELD with REGION one of %s and FIELD one " ..
                            "of %s (e.g. penumbra.rmse; a bare FIELD means all.FIELD)", tostring(path),
                            table.concat(records.metric_regions, ", "), table.concat(records.metric_fields, ", "))
end

for _, c in ipairs(records.work_counters) do -- their columns, after lit_candidates, before the machine's
  table.insert(records.standard_columns, #records.standard_columns - 5, { c[1], work(c[3], c[4]) })
end
-- The getter of a work counter's column (a name of records.work_counters).
function records.work_value(name, row)
  for _, c in ipairs(records.work_counters) do
    if c[1] == name then return work(c[3], c[4])(row) end
  end
  error("records: unknown work counter " .. tostring(name), 2)
end

local standard_getter = {}
for _, c in ipairs(records.standard_columns) do standard_getter[c[1]] = c[2] end

function records.column_value(name, row)
  if standard_getter[name] then return standard_getter[name](row) end
  local param = name:match("^param:(.+)$")
  if param then return row.params and row.params[param] end
  local override = name:match("^scene:(.+)$")
  if override then return row.variant and row.variant.overrides and row.variant.overrides[override] end
  error("records: unknown column " .. name, 2)
end

local function csv_field(v)
  if v == nil or v == json.null then return "" end
  if type(v) == "table" then v = json.encode(v) end
  if math.type(v) == "float" then v = string.format("%.9g", v) end
  local s = tostring(v)
  if s:find('[,"\n\r]') then s = '"' .. s:gsub('"', '""') .. '"' end
  return s
end

function records.csv_line(columns, row)
  local out = {}
  for i, name in ipairs(columns) do out[i] = csv_field(records.column_value(name, row)) end
  return table.concat(out, ",") .. "\n"
end

function records.csv_text(columns, rows)
  local parts = { table.concat(columns, ",") .. "\n" }
  for _, row in ipairs(rows) do parts[#parts + 1] = records.csv_line(columns, row) end
  return table.concat(parts)
end

-- An experiment's own table: `header` (names) and `rows` (arrays of values,
-- written as csv_line writes record columns), atomically to `path`.
function records.write_table(path, header, rows)
  local parts = { table.concat(header, ",") .. "\n" }
  for _, r in ipairs(rows) do
    local f = {}
    for i = 1, #header do f[i] = csv_field(r[i]) end
    parts[#parts + 1] = table.concat(f, ",") .. "\n"
  end
  sl.write_file(path, table.concat(parts))
end

---------------------------------------------------------------- writing

local Writer = {}
Writer.__index = Writer

local function open_append(path)
  local f, msg = io.open(path, "ab")
  if not f then error(msg, 0) end
  f:setvbuf("full", 1 << 22) -- a row goes out in one write()
  return f
end

local function folder_of(path) return path:match("^(.*)/[^/]*$") or "." end

local function file_text(header, rows)
  local lines = { json.encode(header) }
  for i, row in ipairs(rows) do lines[i + 1] = json.encode(row) end
  return table.concat(lines, "\n") .. "\n"
end

-- Open the results `jsonl_path` (and its CSV `csv_path`) for appending.
-- A new file starts with `header`. An existing one must carry the same
-- header.fingerprint (the same experiment), else it is refused; its rows
-- are kept (writer.rows, writer.done[key]) and a half-written last row is
-- dropped (writer.dropped = 1); rows that keep(row) refuses are dropped too
-- (writer.retried counts them: a sweep retries its failed configurations).
-- CSV columns come from header.columns.
function records.open(jsonl_path, csv_path, header, keep)
  local w = setmetatable({ path = jsonl_path, csv_path = csv_path, columns = header.columns,
                           rows = {}, done = {}, dropped = 0, retried = 0 }, Writer)
  local old, rows, dropped = records.read(jsonl_path)
  if old then
    if old.fingerprint ~= header.fingerprint then
      error(string.format("%s holds experiment '%s' (fingerprint %s, settings %s); this run is '%s' (%s, %s): " ..
                          "use another --out, or --fresh to discard it", jsonl_path, tostring(old.name),
                          tostring(old.fingerprint), json.encode(old.settings or {}), header.name,
                          header.fingerprint, json.encode(header.settings)), 0)
    end
    w.dropped = dropped
    for _, row in ipairs(rows) do
      if not keep or keep(row) then w.rows[#w.rows + 1] = row else w.retried = w.retried + 1 end
    end
    if dropped + w.retried > 0 then sl.write_file(jsonl_path, file_text(old, w.rows)) end
  else
    sl.write_file(jsonl_path, file_text(header, {}))
    sl.fsync_dir(folder_of(jsonl_path))
  end
  for _, row in ipairs(w.rows) do w.done[row.key] = row end
  sl.write_file(csv_path, records.csv_text(w.columns, w.rows))
  w.jsonl, w.csv = open_append(jsonl_path), open_append(csv_path)
  return w
end

-- Append one row to both files, each written, flushed and fsynced.
function Writer:append(row)
  if self.done[row.key] then error("records: configuration " .. row.key .. " is already recorded", 2) end
  self.jsonl:write(json.encode(row), "\n")
  sl.fsync(self.jsonl)
  self.csv:write(records.csv_line(self.columns, row))
  sl.fsync(self.csv)
  self.rows[#self.rows + 1] = row
  self.done[row.key] = row
end

function Writer:close()
  if self.jsonl then self.jsonl:close() end
  if self.csv then self.csv:close() end
  self.jsonl, self.csv = nil, nil
end

---------------------------------------------------------------- comparing

-- A row without what differs between two runs of the same configuration:
-- timings, resource build/reuse, cache states, machine and its load, output paths. Two
-- runs agree when their comparable rows encode to the same JSON.
local run_specific = {
  record = { timings_s = true, resources = true, technique_resources = true, resource_cache = true,
             machine = true },
  reference = { origin = true, seconds = true, rays_per_second = true, cache_path = true, cache_note = true },
}

function records.comparable(row)
  local copy = {}
  for k, v in pairs(row) do copy[k] = v end
  copy.load = nil -- the machine's load average when the row ran (experiment.lua)
  if row.record then
    local rec = {}
    for k, v in pairs(row.record) do
      if not run_specific.record[k] then rec[k] = v end
    end
    if rec.reference then
      local ref = {}
      for k, v in pairs(rec.reference) do
        if not run_specific.reference[k] then ref[k] = v end
      end
      rec.reference = ref
    end
    copy.record = rec
  end
  return copy
end

return records
