-- lab-questions.lua LAB DIR -- every question at the top of a lab's report
-- is answerable from DIR/index.html alone: for each question, the things
-- its own words cite (a table column, a plot, the images, a marker) are in
-- the page. Unresolved marks are checked against the records: one marked
-- cell per region whose reference noise exceeds half its error.
-- Prints "LAB: N questions answerable" or fails naming the question and
-- what it cites that is missing.
local json = require "shadowlab.json"

local lab, dir = arg[1], arg[2]

-- What each question cites, in its own words, and how the page shows it:
-- a literal string of index.html (a column header, a caption, a plot's
-- file) or of one of the plots it shows (in_plots: the SVG's text).
local header = function(name) return { what = "the table's " .. name .. " column", text = "<th>" .. name } end
local plot = function(stem) return { what = "the " .. stem .. " plot", text = 'src="plots/' .. stem } end
local signed_errors = { what = "the signed-error images", text = "signed error, ±" }
local noise_line = { what = "the dashed noise line", text = "dashed: reference", in_plots = true }
local unresolved = { what = "rows marked unresolved", unresolved = true }
local front = { what = "the Pareto front", text = "Pareto front" }
local cold_warm = { what = "the resources column (cold / warm)", text = "<th>resources" }
local frame_def = { what = "the definition of frame time", text = "<b>Frame time</b>" }

local cites = {
  ["lab-light-radius"] = {
    { plot("error-vs-lights-1-radius"), header("reference penumbra samples") },
    { header("all RMSE") },
    { plot("cost-vs-lights-1-radius") },
    { header("umbra RMSE"), header("penumbra RMSE"), header("lit RMSE"), signed_errors },
    { header("noise rms"), noise_line, unresolved },
  },
  ["lab-aliasing"] = {
    { header("misclassified"), header("false shadow"), header("false lit"),
      { what = "the signed-error images against the truth", text = "signed error against the truth" },
      { what = "the colour bar", text = '<div class="key">' } },
    { plot("aliasing-depth"), header("e_x (across)"), header("e_y (along the view)") },
    { header("m_s max"), header("m_t max"), header("m_s max x m_t max") },
    { header("undersampled (m &gt; 1)"), { what = "the m maps' colour key", text = "Key of the m maps" },
      header("storage factor") },
    { header("fitted z (ends near)"), header("camera z_f") },
  },
  ["lab-kernel-size"] = {
    { plot("error-vs-K"), header("penumbra RMSE") },
    { cold_warm, frame_def },
    { plot("cost-vs-K") },
    { signed_errors },
    { plot("error-vs-time"), front },
  },
}

local function read(path)
  local f = assert(io.open(path, "rb"), "cannot open " .. path)
  local s = f:read("a")
  f:close()
  return s
end

-- Cells the records say must be marked: resolved false with some noise.
local function expected_unresolved()
  local n = 0
  local f = assert(io.open(dir .. "/records.jsonl"))
  f:read("l") -- the header
  for line in f:lines() do
    local r = json.decode(line)
    if r.status == "ok" then
      for _, g in ipairs({ "umbra", "penumbra", "lit", "terminator", "all" }) do
        local m = r.record.metrics[g]
        if type(m) == "table" and m.resolved == false and type(m.noise_rms) == "number" and m.noise_rms > 0 then
          n = n + 1
        end
      end
    end
  end
  f:close()
  return n
end

local page = read(dir .. "/index.html")
local list = cites[lab] or error("lab-questions: no citations listed for " .. tostring(lab))
local shown = select(2, page:gsub("<li>", ""))
if shown ~= #list then error(string.format("%s: index.html lists %d questions, the test knows %d", lab, shown, #list), 0) end
local missing = {}
for q, needs in ipairs(list) do
  for _, c in ipairs(needs) do
    local found
    if c.unresolved then
      local want = expected_unresolved()
      local got = select(2, page:gsub('class="n unres"', ""))
      found = want > 0 and got == want
      if not found then c.what = string.format("%s (%d marked, records say %d)", c.what, got, want) end
    elseif c.in_plots then
      for svg in page:gmatch('src="(plots/[^"]+%.svg)"') do
        found = found or read(dir .. "/" .. svg):find(c.text, 1, true) ~= nil
      end
    else found = page:find(c.text, 1, true) ~= nil end
    if not found then missing[#missing + 1] = string.format("Q%d cites %s", q, c.what) end
  end
end
if #missing > 0 then error(lab .. ": index.html lacks what its questions cite: " .. table.concat(missing, "; "), 0) end
print(string.format("%s: %d questions answerable", lab, #list))
