-- test_helpers.lua -- tests of the pure-Lua helpers (json, sweep, pareto,
-- records, experiment, autotune, plot) and of the module's refusals, run by
-- `shadowlab run`. Prints "ok NAME" or "FAIL NAME: why" per test; the exit
-- status is the number of failures (tests/lua/run.sh counts the lines).
local sl = require "shadowlab"
local json = require "shadowlab.json"
local sweep = require "shadowlab.sweep"
local pareto = require "shadowlab.pareto"
local records = require "shadowlab.records"
local experiment = require "shadowlab.experiment"
local autotune = require "shadowlab.autotune"

local tmp = assert(arg[1], "usage: test_helpers.lua TMPDIR")
local small = { ["camera.width"] = 40, ["camera.height"] = 30 }
local tests, failed = {}, 0

local function test(name, fn) tests[#tests + 1] = { name = name, fn = fn } end

local function expect_error(fn, ...)
  local ok, msg = pcall(fn)
  if ok then error("expected an error", 2) end
  msg = tostring(msg)
  for _, word in ipairs({ ... }) do
    if not msg:find(word, 1, true) then error(string.format("error lacks '%s': %s", word, msg), 2) end
  end
  return msg
end

local function deep_equal(a, b)
  if type(a) ~= type(b) then return false end
  if type(a) ~= "table" then return a == b or (a ~= a and b ~= b) end
  for k, v in pairs(a) do
    if not deep_equal(v, b[k]) then return false end
  end
  for k in pairs(b) do
    if a[k] == nil then return false end
  end
  return true
end

---------------------------------------------------------------- json

test("json_round_trips_values_exactly", function()
  local value = { s = 'quote " backslash \\ tab \t newline \n é ☃ \1', i = -42, big = 1 << 53,
                  f = { 0.1, 1e-300, 2.5e300, -0.0, 2 ^ 60, 1 / 3, 123456.789 }, t = true, n = false,
                  empty_array = json.as_array({}), empty_object = {}, nested = { { a = { 1, 2, { b = json.null } } } } }
  local text = json.encode(value)
  assert(not text:find("\n"), "one line")
  local back = json.decode(text)
  assert(deep_equal(back, value), "decode(encode(v)) == v")
  assert(json.encode(back) == text, "encode is deterministic")
  assert(math.type(back.i) == "integer" and math.type(back.f[5]) == "float", "integer and float kept apart")
  assert(json.encode(json.decode("[]")) == "[]" and json.encode(json.decode("{}")) == "{}")
  assert(json.decode('"\\ud83d\\ude00"') == "😀", "surrogate pairs")
end)

test("json_errors_say_where", function()
  expect_error(function() json.decode('{"a": 1,\n "b": }') end, "line 2")
  expect_error(function() json.decode('{"a": 1} x') end, "trailing")
  expect_error(function() json.decode('{"a": "unterminated') end, "unterminated")
end)

---------------------------------------------------------------- sweep

test("sweep_grid_is_the_cartesian_product", function()
  local points = sweep.grid{ a = { 1, 2, 3 }, b = { "x", "y" } }
  assert(#points == 6)
  local seen = {}
  for _, p in ipairs(points) do seen[p.a .. p.b] = (seen[p.a .. p.b] or 0) + 1 end
  for _, a in ipairs({ 1, 2, 3 }) do
    for _, b in ipairs({ "x", "y" }) do assert(seen[a .. b] == 1, "combination " .. a .. b) end
  end
  expect_error(function() sweep.grid{ a = {} } end, "non-empty")
end)

test("sweep_zip_pairs_elements", function()
  local points = sweep.zip{ K = { 1, 3, 5 }, map_size = { 256, 512, 1024 } }
  assert(#points == 3 and points[2].K == 3 and points[2].map_size == 512)
  expect_error(function() sweep.zip{ K = { 1, 3 }, map_size = { 1 } } end, "map_size")
end)

test("sweep_latin_has_one_sample_per_stratum", function()
  local n = 16
  local points = sweep.latin({ x = { 0, 1 }, k = { 1, 64, "int log" }, r = { 0.01, 1, "log" } }, n, 7)
  assert(#points == n)
  local strata_x, strata_r = {}, {}
  for _, p in ipairs(points) do
    assert(p.x >= 0 and p.x < 1 and math.type(p.k) == "integer" and p.k >= 1 and p.k <= 64)
    strata_x[math.floor(p.x * n)] = true
    strata_r[math.floor((math.log(p.r) - math.log(0.01)) / (math.log(1) - math.log(0.01)) * n)] = true
  end
  for s = 0, n - 1 do assert(strata_x[s] and strata_r[s], "stratum " .. s .. " holds a sample") end
  assert(deep_equal(points, sweep.latin({ x = { 0, 1 }, k = { 1, 64, "int log" }, r = { 0.01, 1, "log" } }, n, 7)),
         "same seed, same points")
  assert(not deep_equal(points, sweep.latin({ x = { 0, 1 }, k = { 1, 64, "int log" }, r = { 0.01, 1, "log" } }, n, 8)),
         "another seed, other points")
  expect_error(function() sweep.latin({ r = { 0, 1, "log" } }, 4, 1) end, "min > 0")
end)

test("sweep_random_stays_in_range_and_ranges_come_from_the_registry", function()
  local hard = sl.technique("hard")
  local ranges = sweep.ranges_of(hard, { "offset_scale" })
  assert(ranges.offset_scale[1] == hard.params[1].min and ranges.offset_scale[2] == hard.params[1].max)
  for _, p in ipairs(sweep.random(ranges, 50, 3)) do
    assert(p.offset_scale >= hard.params[1].min and p.offset_scale <= hard.params[1].max)
  end
  expect_error(function() sweep.ranges_of(hard, { "nope" }) end, "nope")
end)

test("technique_param_by_name_is_the_params_list_entry", function()
  for _, t in ipairs(sl.techniques()) do
    local named = 0
    for _ in pairs(t.param) do named = named + 1 end
    assert(named == #t.params, string.format("%s: %d parameters by name, %d in the list", t.name, named, #t.params))
    for _, p in ipairs(t.params) do
      assert(rawequal(t.param[p.name], p), t.name .. ".param." .. p.name .. " is not its params entry")
    end
  end
  assert(sl.technique("hard").param.K == nil, "hard has no K")
end)

test("sweep_random_gives_every_integer_of_a_range_equal_weight", function()
  -- 40,000 draws over [1, 4]: each value 10,000 +- 4 sigma (sigma = sqrt(40000 * 1/4 * 3/4) = 86.6);
  -- rounding to the nearest gave the endpoints half weight (about 6,650 each).
  local counts = {}
  for _, p in ipairs(sweep.random({ k = { 1, 4, "int" } }, 40000, 5)) do counts[p.k] = (counts[p.k] or 0) + 1 end
  for k = 1, 4 do
    assert(math.abs((counts[k] or 0) - 10000) < 4 * 86.6, string.format("value %d drawn %d times", k, counts[k] or 0))
  end
  assert(next(counts) and counts[0] == nil and counts[5] == nil)
  -- "int log" over [1, 64]: k owns log((k + 1) / k) / log(65) of the draws.
  local logc, n = {}, 40000
  for _, p in ipairs(sweep.random({ k = { 1, 64, "int log" } }, n, 9)) do logc[p.k] = (logc[p.k] or 0) + 1 end
  for _, k in ipairs({ 1, 2, 8, 64 }) do
    local want = n * math.log((k + 1) / k) / math.log(65)
    local sigma = math.sqrt(want * (1 - want / n))
    assert(math.abs((logc[k] or 0) - want) < 4 * sigma + 1, string.format("k = %d: %d, expected %.0f", k, logc[k] or 0, want))
  end
  expect_error(function() sweep.random({ k = { 1.2, 1.8, "int" } }, 4, 1) end, "no integer")
end)

test("sweep_latin_over_as_many_integers_as_samples_hits_each_once", function()
  -- n = 4 over [1, 4]: one sample per stratum is one of each value, for every seed
  -- (the old rounding missed a value in 559 of 1000 seeds).
  for seed = 1, 1000 do
    local seen = {}
    for _, p in ipairs(sweep.latin({ k = { 1, 4, "int" } }, 4, seed)) do seen[p.k] = true end
    for k = 1, 4 do assert(seen[k], string.format("seed %d misses %d", seed, k)) end
  end
end)

---------------------------------------------------------------- pareto

test("pareto_front_matches_brute_force", function()
  local u = sweep.rng(11)
  for trial = 1, 20 do
    local points = {}
    for i = 1, 40 do points[i] = { x = math.floor(u() * 20), y = math.floor(u() * 20), id = i } end
    local front = pareto.front(points)
    local on = {}
    for _, p in ipairs(front) do on[p.id] = true end
    for _, p in ipairs(points) do
      local dominated = false
      for _, q in ipairs(points) do dominated = dominated or pareto.dominates(q, p) end
      assert((on[p.id] or false) == not dominated, string.format("trial %d point %d (%g, %g)", trial, p.id, p.x, p.y))
    end
    for i = 2, #front do assert(front[i].x >= front[i - 1].x and front[i].y <= front[i - 1].y, "sorted staircase") end
  end
end)

---------------------------------------------------------------- records

local function header(fp) return { shadowlab_results = 1, name = "t", fingerprint = fp, settings = {},
                                   columns = { "index", "key", "status", "rmse" } } end

local function line_count(path)
  local n = 0
  for _ in io.lines(path) do n = n + 1 end
  return n
end

test("records_drop_a_half_written_last_row_and_keep_the_rest", function()
  local path, csv = tmp .. "/rec.jsonl", tmp .. "/rec.csv"
  local w = records.open(path, csv, header("f1"))
  w:append{ index = 0, key = "a", status = "ok" }
  w:append{ index = 1, key = "b", status = "ok" }
  w:close()
  local f = assert(io.open(path, "ab"))
  f:write('{"index":2,"key":"c","sta') -- a row cut short, as by kill -9 or power loss
  f:close()
  local h, rows, dropped = records.read(path)
  assert(h.fingerprint == "f1" and #rows == 2 and dropped == 1, "two rows kept, one dropped")
  w = records.open(path, csv, header("f1"))
  assert(w.dropped == 1 and w.done.a and w.done.b and not w.done.c)
  w:append{ index = 2, key = "c", status = "ok" }
  expect_error(function() w:append{ index = 3, key = "a" } end, "already recorded")
  w:close()
  local _, again, dropped2 = records.read(path)
  assert(#again == 3 and dropped2 == 0 and again[3].key == "c")
  assert(line_count(csv) == 4, "the CSV has a header and the three rows")
end)

test("records_drop_rows_to_retry_and_rewrite_the_file", function()
  local path, csv = tmp .. "/retry.jsonl", tmp .. "/retry.csv"
  local w = records.open(path, csv, header("f1"))
  w:append{ index = 0, key = "a", status = "ok" }
  w:append{ index = 1, key = "b", status = "error", error = "out of memory" }
  w:close()
  local ok_only = function(row) return row.status == "ok" end
  w = records.open(path, csv, header("f1"), ok_only)
  assert(w.retried == 1 and w.done.a and not w.done.b, "the failed row is to be retried")
  w:close()
  local _, rows = records.read(path)
  assert(#rows == 1 and rows[1].key == "a", "and it is gone from the file")
end)

test("records_refuse_a_corrupt_middle_line_and_another_experiment", function()
  local path = tmp .. "/bad.jsonl"
  sl.write_file(path, json.encode(header("f1")) .. '\n{"key":"a"}\n{"key": oops}\n{"key":"b"}\n')
  expect_error(function() records.read(path) end, path .. ":3:")
  local good = tmp .. "/good.jsonl"
  records.open(good, tmp .. "/good.csv", header("f1")):close()
  expect_error(function() records.open(good, tmp .. "/good.csv", header("f2")) end, "fingerprint f1", "--fresh")
end)

---------------------------------------------------------------- experiment and module refusals

test("experiment_refuses_bad_parameters_before_running_anything", function()
  local e = experiment.new{ name = "bad" }
  expect_error(function() e:add("hard", { { offset_scale = -1 } }) end, "offset_scale", "[0, 10000]")
  expect_error(function() e:add("hard", { { nope = 1 } }) end, "unknown parameter 'nope'", "offset_scale")
  expect_error(function() e:add("hard", { { offset_scale = "wide" } }) end, "offset_scale", "wide")
  expect_error(function() e:add("no-such-technique") end, "unknown technique", "hard")
  expect_error(function() experiment.new{ name = "x", sampels = 3 } end, "unknown field 'sampels'")
  expect_error(function() experiment.new{ name = "a b" } end, "name")
end)

test("module_refuses_bad_options_and_parameters", function()
  local lab = sl.open("scenes/sphere-on-plane.lua", small)
  expect_error(function() lab:compare{ technique = "hard", params = { offset_scale = 1e9 } } end, "offset_scale",
               "[0, 10000]")
  expect_error(function() lab:render{ technique = "hard", repeats = 0 } end, "repeats", "[1, 10000]")
  expect_error(function() lab:render{ technique = "hard", light = 2 } end, "light 2", "[1, 1]")
  expect_error(function() lab:reference{ pattern = "sobol" } end, "sobol")
  expect_error(function() lab:compare{ params = {} } end, "technique is required")
  expect_error(function() sl.open("scenes/sphere-on-plane.lua", { ["lights[1].radius"] = -1 }) end,
               "lights[1].radius")
  for _, t in ipairs(sl.techniques()) do
    for _, p in ipairs(t.params) do
      if p.type == "int" or p.type == "float" then
        expect_error(function() sl.params(t.name, { [p.name] = p.max + 1 }) end, p.name, p.range)
      end
    end
  end
  lab:close()
end)

test("configuration_keys_are_stable_and_depend_on_the_scene_and_every_parameter", function()
  local a = sl.open("scenes/sphere-on-plane.lua", small)
  local b = sl.open("scenes/sphere-on-plane.lua", { ["camera.height"] = 30, ["camera.width"] = 40 })
  local c = sl.open("scenes/sphere-on-plane.lua", { ["camera.width"] = 40, ["camera.height"] = 30,
                                                   ["lights[1].radius"] = 0.3 })
  assert(a:key("hard", {}) == b:key("hard", { offset_scale = 1.0 }), "same scene content, same parameters")
  assert(a:key("hard", {}) ~= c:key("hard", {}), "another light, another key")
  assert(a:key("hard", { offset_scale = 2 }) ~= a:key("hard", {}), "another value, another key")
  for _, lab in ipairs({ a, b, c }) do lab:close() end
end)

test("experiment_runs_a_configuration_listed_twice_once", function()
  local e = experiment.new{ name = "twice", samples = 4, repeats = 1, warmup = 0, overrides = small }
  e:scene("scenes/sphere-on-plane.lua")
  e:add("hard")
  e:add("hard", { { offset_scale = 1 }, { offset_scale = 2 }, { offset_scale = 2 } })
  local r = e:run({ "--out", tmp .. "/twice", "--no-images", "--quiet" })
  assert(#r.rows == 2 and r.computed == 2, "rows " .. #r.rows)
end)

test("experiment_drops_resources_past_its_memory_budget", function()
  local function map_actions(budget)
    local e = experiment.new{ name = "budget", samples = 4, repeats = 1, warmup = 0, overrides = small,
                              resource_budget_gib = budget }
    e:scene("scenes/sphere-on-plane.lua")
    e:add("pcf", { { K = 1 }, { K = 3 } })
    local r = e:run({ "--out", tmp .. "/budget-" .. budget, "--no-images", "--quiet" })
    local actions = {}
    for i, row in ipairs(r.rows) do
      for _, ev in ipairs(row.record.technique_resources) do
        if ev.kind == "shadow_map" then actions[i] = ev.action end
      end
    end
    return table.concat(actions, " ")
  end
  local within, past = map_actions(2), map_actions(0)
  assert(within == "built reused", "within the budget the second K reuses the map: " .. within)
  assert(past == "built built", "past it every configuration starts afresh: " .. past)
end)

test("autotune_returns_the_best_feasible_point_it_evaluated", function()
  local lab = sl.open("scenes/sphere-on-plane.lua", small)
  local r = autotune.run{ lab = lab, technique = "hard", budget_s = 1e3, evaluations = 6, initial = 3, samples = 8,
                          repeats = 1, cache = false }
  assert(#r.history <= 6 and #r.history >= 4, "evaluations: " .. #r.history)
  assert(r.feasible and r.best.feasible)
  for _, p in ipairs(r.history) do
    assert(p.error >= r.best.error, "no evaluated point beats the best")
    assert(p.params.offset_scale >= 0 and p.params.offset_scale <= 1e4)
  end
  local none = autotune.run{ lab = lab, technique = "hard", budget_s = 0, evaluations = 3, initial = 2, samples = 8,
                             repeats = 1, cache = false }
  assert(not none.feasible, "nothing fits a zero budget")
  for _, p in ipairs(none.history) do assert(p.time >= none.best.time, "infeasible: the fastest is reported") end
  lab:close()
end)

test("autotune_defaults_to_the_main_parameter_and_the_map_size", function()
  local function names(t) return table.concat(autotune.default_params(sl.technique(t)), " ") end
  assert(names("pcf") == "K map_size", "pcf: " .. names("pcf"))
  assert(names("sm") == "map_size", "sm: " .. names("sm"))
  assert(names("hard") == "offset_scale", "hard: " .. names("hard"))
end)

test("autotune_skips_and_reports_refused_points", function()
  -- explicit splits with split_1 given: only cascades = 2 is accepted, every other
  -- value is refused by the engine, and the search goes on past each refusal
  local lab = sl.open("scenes/sphere-on-plane.lua", small)
  local r = autotune.run{ lab = lab, technique = "pcf", params = { "cascades" }, budget_s = 1e3, evaluations = 5,
                          initial = 3, samples = 4, repeats = 1, warmup = 0, cache = false,
                          fixed = { split_scheme = "explicit", split_1 = 3, map_size = 64 } }
  assert(#r.refused >= 1, "some cascade counts are refused")
  for _, p in ipairs(r.refused) do
    assert(p.params.cascades ~= 2 and p.message:find("split", 1, true), "refused: " .. tostring(p.message))
  end
  for _, p in ipairs(r.history) do assert(p.params.cascades == 2, "only cascades = 2 runs") end
  assert(#r.history + #r.refused <= 5, "refusals count as evaluations")
  lab:close()
end)

test("autotune_searches_a_zero_based_range_over_decades_in_log", function()
  -- hard's offset_scale in [0, 1e4], default 1: the Latin start lies in [1e-3, 1e4] spread in
  -- log (linear strata of 1e4 / 3 would put every start above 1000)
  local lab = sl.open("scenes/sphere-on-plane.lua", small)
  local r = autotune.run{ lab = lab, technique = "hard", budget_s = 1e3, evaluations = 4, initial = 3, samples = 4,
                          repeats = 1, warmup = 0, cache = false }
  local below = 0
  for _, p in ipairs(r.history) do
    if p.params.offset_scale < 100 then below = below + 1 end
  end
  assert(below >= 2, "points below 100 of 4: " .. below)
  lab:close()
end)

test("autotune_measures_a_point_just_over_the_budget_twice", function()
  -- a stand-in lab whose first measurement of each point is slow: 1.5x the budget is measured
  -- again (and kept when faster), 5x is not
  local calls = {}
  local fake = { compare = function(_, opts)
    local id = json.encode(opts.params)
    calls[id] = (calls[id] or 0) + 1
    local t = opts.params.offset_scale == 1 and (calls[id] == 1 and 0.015 or 0.008) or 0.05
    return { record = function() return { metrics = { all = { rmse = 0.1 } }, timings_s = { frame = t } } end }
  end }
  local r = autotune.run{ lab = fake, technique = "hard", budget_s = 0.01, evaluations = 3, initial = 2 }
  local default = r.history[1]
  assert(default.params.offset_scale == 1 and default.measured == 2 and default.time == 0.008 and default.feasible,
         "the default point is measured twice and fits")
  for i = 2, #r.history do assert(not r.history[i].measured and not r.history[i].feasible) end
  assert(r.best == default)
end)

test("records_carry_the_scene_overrides_as_written", function()
  local lab = sl.open("scenes/sphere-on-plane.lua", { ["lights[1].radius"] = 0.1, ["camera.width"] = 16,
                                                       ["camera.height"] = 12 })
  local rec = lab:compare{ technique = "hard", samples = 4 }:record()
  lab:close()
  local text = table.concat(rec.scene.overrides, " ")
  assert(text == "camera.height=12 camera.width=16 lights[1].radius=0.1", "overrides: " .. text)
end)

test("experiment_refuses_an_unknown_metric_before_running", function()
  expect_error(function() experiment.new{ name = "bad-metric", error = "penumbra_rmse" } end,
               "unknown error metric 'penumbra_rmse'", "penumbra.rmse", "terminator")
end)

test("experiment_progress_prints_the_metric_its_report_plots", function()
  local out = tmp .. "/progress"
  local exp = experiment.new{ name = "progress", samples = 4, repeats = 1, warmup = 0, error = "penumbra.rmse",
                              overrides = { ["camera.width"] = 16, ["camera.height"] = 12 } }
  exp:scene("scenes/sphere-on-plane.lua")
  exp:add("hard")
  local lines = {}
  local real = io.stderr
  io.stderr = { write = function(_, ...) for _, s in ipairs({ ... }) do lines[#lines + 1] = s end end }
  local ok, err = pcall(function() exp:run({ "--out", out, "--no-images" }) end)
  io.stderr = real
  assert(ok, tostring(err))
  local text = table.concat(lines)
  assert(text:find("penumbra.rmse ", 1, true), "progress lines: " .. text)
end)

---------------------------------------------------------------- plots

local function fake_row(scene, samples, noise)
  return { record = { scene = { name = scene, width = 40, height = 30 }, reference = { samples = samples },
                      metrics = { all = { noise_rms = noise } } } }
end

local function read_all(path)
  local f = io.open(path, "rb")
  if not f then return nil end
  local text = f:read("a")
  f:close()
  return text
end

test("plot_subtitles_state_scene_resolution_samples_and_noise_from_the_rows", function()
  local plot = require "shadowlab.plot"
  local rows = { fake_row("ball", 64, 0.002), fake_row("ball", 64, 0.004), fake_row("box", 16, 0.01) }
  assert(plot.caption(rows) == "ball 40x30, reference 64 samples, noise rms 0.0020-0.0040; " ..
                               "box 40x30, reference 16 samples, noise rms 0.0100", plot.caption(rows))
  local series = { { title = "a", points = { { 1, 1 }, { 2, 3 } } } }
  plot.draw(tmp .. "/plots", "cap", { title = "T", subtitle = "extra", xlabel = "x", ylabel = "y", series = series,
                                      rows = rows })
  local gp = read_all(tmp .. "/plots/cap.gp")
  assert(gp:find("\\nball 40x30, reference 64 samples", 1, true) and gp:find("\\nbox 40x30", 1, true) and
         gp:find("\\nextra", 1, true), "subtitle")
  expect_error(function() plot.draw(tmp .. "/plots", "bare", { title = "T", xlabel = "x", ylabel = "y",
                                                               series = series }) end, "spec.rows")
  plot.draw(tmp .. "/plots", "closed", { title = "T", xlabel = "x", ylabel = "y", series = series,
                                         analytic = "y = x^2" })
  assert(read_all(tmp .. "/plots/closed.gp"):find("closed form: y = x^2", 1, true))
end)

test("plot_subtitles_say_one_exact_ray_for_delta_lights_and_skip_absent_noise", function()
  local plot, json = require "shadowlab.plot", require "shadowlab.json"
  local delta = { record = { scene = { name = "cones", width = 40, height = 30 },
                             reference = { samples = 1024, std_error = "exact" },
                             metrics = { all = { noise_rms = 0 }, penumbra = { count = 0, noise_rms = json.null } } } }
  assert(plot.caption({ delta }) == "cones 40x30, reference one exact ray (delta light), noise rms 0.0000",
         plot.caption({ delta }))
  local penumbra = { label = "noise rms (penumbra)", value = function(rec) return rec.metrics.penumbra.noise_rms end }
  local text = plot.caption({ delta }, nil, penumbra)
  assert(text == "cones 40x30, reference one exact ray (delta light), noise rms (penumbra) none", text)
end)

test("plot_images_appear_whole_or_not_at_all", function()
  local plot = require "shadowlab.plot"
  local dir = tmp .. "/atomic"
  local spec = { title = "T", xlabel = "x", ylabel = "y", rows = { fake_row("ball", 8, 0.1) },
                 series = { { title = "a", points = { { 1, 1 }, { 2, 3 } } } } }
  plot.draw(dir, "p", spec)
  local svg, png = read_all(dir .. "/p.svg"), read_all(dir .. "/p.png")
  assert(svg and svg:find("</svg>", 1, true) and png and #png > 100, "both images written whole")
  -- gnuplot failing half-way (no valid point to plot) leaves the old images as they were, and no temporary
  spec.series = { { title = "a", points = {} } }
  expect_error(function() plot.draw(dir, "p", spec) end, "gnuplot failed")
  assert(read_all(dir .. "/p.svg") == svg and read_all(dir .. "/p.png") == png, "old images untouched")
  for _, name in ipairs(sl.dir(dir)) do assert(not name:find("partial", 1, true), "left behind: " .. name) end
end)

---------------------------------------------------------------- reproduce

test("reproduce_judges_each_rule_and_writes_one_csv_row_per_item", function()
  local reproduce = require "shadowlab.reproduce"
  local dir = tmp .. "/reproduce"
  local src = "test"
  local rows = {
    { item = "equal", paper = 2, measured = 2.1, rule = reproduce.within(0.1), source = src },
    { item = "far", paper = 2, measured = 3, rule = reproduce.within(0.1), source = src },
    { item = "in size", paper = 2, measured = 3, rule = reproduce.factor(2), source = src },
    { item = "grows", paper = 3, measured = 1.2, rule = reproduce.trend(0.5), source = src },
    { item = "grows, close", paper = 1.8, measured = 1.7, rule = reproduce.trend(0.5), source = src },
    { item = "shrinks", paper = 1.8, measured = 0.9, rule = reproduce.trend(0.5), source = src },
    { item = "claim, with a comma", paper = 1, measured = 0.5, rule = reproduce.below(), source = src },
    { item = "claim broken", paper = 0, measured = -1, rule = reproduce.above(), source = src },
    { item = "nan", paper = 1, measured = 0 / 0, rule = reproduce.within(0.1), source = src },
    { item = "missing", paper = 1, rule = reproduce.below(), source = src },
  }
  local rep = reproduce.compare(rows, { out = dir, title = "T", quiet = true })
  local want = { "matches within 10%", "differs (x1.5)", "matches within a factor 2", "trend matches",
                 "trend matches within 50%", "trend differs", "claim holds", "differs", "not measured",
                 "not measured" }
  for i, v in ipairs(want) do assert(rep.rows[i].verdict == v, rows[i].item .. ": " .. rep.rows[i].verdict) end
  assert(rep.failed == 5, "failed count " .. rep.failed)
  assert(rep.rows[8].ratio ~= rep.rows[8].ratio, "a ratio to a paper value of 0 is undefined, not a number")
  local csv = read_all(dir .. "/reproduction.csv")
  assert(select(2, csv:gsub("\n", "")) == #rows + 1, "a header and one line per item")
  assert(csv:find('"claim, with a comma"', 1, true), "fields with commas are quoted")
  assert(csv:find("\nnan,,,1,nan,nan,", 1, true), "NaN kept as NaN: " .. csv)
  assert(rep.html:find("<table", 1, true) and read_all(dir .. "/reproduction.md"):find("| equal |", 1, true))
  expect_error(function() reproduce.compare({ { item = "x", paper = 0 / 0, measured = 1, rule = reproduce.below(),
                                                source = src } }, { out = dir, title = "T", quiet = true }) end, "finite")
  expect_error(function() reproduce.compare({ { item = "x", paper = 1, measured = 1, rule = reproduce.below() } },
                                            { out = dir, title = "T", quiet = true }) end, "source")
end)

-- Occluder fusion (lua/shadowlab/fusion.lua, experiments/soft-failures.lua):
-- the rules of course Fig. 1.6 and the nearest-rule classification, on
-- synthetic visibilities where the answer is known.
test("fusion_combines_occlusions_by_sum_product_and_max", function()
  local fusion = require "shadowlab.fusion"
  local c = fusion.combine(0.75, 0.5) -- occlusions 0.25 and 0.5
  assert(math.abs(c.sum - 0.25) < 1e-12 and math.abs(c.product - 0.375) < 1e-12 and c.max == 0.5,
         string.format("sum %g product %g max %g", c.sum, c.product, c.max))
  assert(fusion.combine(0.2, 0.3).sum == 0, "the sum of occlusions clamps at no light left")
  assert(fusion.in_region(0.5, 0.5) and not fusion.in_region(1, 0.5) and not fusion.in_region(0.5, 0),
         "only samples both occluders alone leave in penumbra can tell the rules apart")
  expect_error(function() fusion.combine(0 / 0, 0.5) end, "v1", "finite")
end)

test("fusion_classifies_an_estimate_as_the_rule_it_follows", function()
  local fusion = require "shadowlab.fusion"
  -- truth: the product (partial overlap); v1, v2 over a grid of penumbra values
  local function samples(rule, noise)
    local out = {}
    for i = 1, 9 do
      for j = 1, 9 do
        local c = fusion.combine(i / 10, j / 10)
        local s = { truth = c.product, sum = c.sum, product = c.product, max = c.max }
        s.estimate = s[rule] + noise * (((i * 7 + j * 3) % 5) - 2) / 2 -- a deterministic +-noise
        out[#out + 1] = s
      end
    end
    return out
  end
  for _, rule in ipairs({ "sum", "max" }) do
    local label, rmse, n = fusion.classify(samples(rule, 0.01))
    assert(label == rule, rule .. " classified as " .. label)
    assert(n == 81 and rmse[rule] < rmse.truth, rule .. ": rmse " .. rmse[rule])
  end
  -- the product is the truth here: both names, since the scene cannot tell them apart
  assert(fusion.classify(samples("product", 0.01)) == "truth=product")
  local label, _, _, bias = fusion.classify(samples("sum", 0))
  assert(label == "sum" and bias < 0, "the sum is darker than the product: signed error " .. bias)
  local none, rmse = fusion.classify({})
  assert(none == "-" and rmse.truth ~= rmse.truth, "no samples: not measured (NaN), never 0")
  expect_error(function()
    fusion.classify({ { estimate = 0 / 0, truth = 0.5, sum = 0.5, product = 0.5, max = 0.5 } })
  end, "samples[1].estimate")
end)

test("scenefile_writes_a_scene_the_engine_reads_back_exactly", function()
  local scenefile = require "shadowlab.scenefile"
  local scene = scenefile.load(sl.root .. "/scenes/parallel-planes.lua")
  scene.lights[1].width, scene.name = 0.1, "derived"
  local path = tmp .. "/derived.lua"
  scenefile.write(path, scene, "a test")
  local back = scenefile.load(path)
  assert(deep_equal(back, scene), "the written scene reads back equal")
  local lab = sl.open(path, small)
  assert(lab:info().name == "derived" and lab:info().lights[1].type == "rect")
  lab:close()
  scene.objects[1].height_fn = function() return 0 end
  expect_error(function() scenefile.write(path, scene) end, "objects[1].height_fn", "function")
end)

for _, t in ipairs(tests) do
  local ok, err = pcall(t.fn)
  if ok then print("ok   " .. t.name) else
    failed = failed + 1
    print("FAIL " .. t.name .. ": " .. tostring(err))
  end
end
return failed
