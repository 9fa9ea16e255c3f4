-- SPDX-License-Identifier: MIT
-- The dissector proper. urrt_lua prints the tables it reads (sizes, VERSIONS,
-- GENERATIONS, the enumerations, FIELDS, LAYOUT) above this from lib/, so
-- nothing about the wire format is written here twice.

local urrt = Proto("urrt", "Universal Robots RealTime")

local FIELD = {}
for _, f in ipairs(FIELDS) do FIELD[f[1]] = f end

-- What a unit string of the table means for display: "enum" and "bits" are
-- codings, "" is no unit.
local function is_unit(unit) return unit ~= "" and unit ~= "enum" and unit ~= "bits" end

local pf = {
    length = ProtoField.int32("urrt.length", "length", base.DEC, nil, nil,
        "Message size in bytes, these 4 included"),
    generation = ProtoField.string("urrt.generation", "generation", base.ASCII,
        "Layout generation the size implies"),
    versions = ProtoField.string("urrt.versions", "versions", base.ASCII,
        "Controller software that sends this size"),
    column = ProtoField.double("urrt.column", "column",
        "A column no field of this layout covers (UR's Gnuplot col.)"),
    skipped = ProtoField.bytes("urrt.skipped", "skipped", base.NONE,
        "Bytes up to the next acceptable header"),
}
for _, f in ipairs(FIELDS) do
    local name, unit, desc = f[1], f[3], f[4]
    if is_unit(unit) then desc = desc .. " [" .. unit .. "]" end
    pf[name] = ProtoField.double("urrt." .. name, name, desc)
end
urrt.fields = pf

local ex = {
    size = ProtoExpert.new("urrt.size.implausible", "Implausible message size",
        expert.group.PROTOCOL, expert.severity.WARN),
    unknown = ProtoExpert.new("urrt.length.unknown", "No known controller sends this length",
        expert.group.PROTOCOL, expert.severity.NOTE),
}
urrt.experts = { ex.size, ex.unknown }

-- Shortest text that reads back as the same double.
local function num(v)
    for _, f in ipairs({ "%.15g", "%.16g", "%.17g" }) do
        local s = f:format(v)
        if tonumber(s) == v then return s end
    end
    return tostring(v)
end

-- As urrt_bitmask(): sign and exponent clear is a raw int64 read as a
-- double, otherwise the double must be a whole number from 0 to 2^53.
local function bitmask(range)
    local raw, v = range:uint64(), range:float()
    if raw:rshift(52) == UInt64(0) then return "0x" .. raw:tohex():gsub("^0+(.)", "%1") end
    if v >= 0 and v <= 2 ^ 53 and v == math.floor(v) then return ("0x%X"):format(v) end
end

-- Unit of element i (0-based) of a field: "m, rad" splits a pose's elements
-- evenly, x y z in m and rx ry rz in rad.
local function unit_of(f, i)
    local units = {}
    for u in f[3]:gmatch("[^,]+") do units[#units + 1] = u:match("^%s*(.-)%s*$") end
    return units[math.floor(i * #units / f[2]) + 1] or ""
end

local function value_text(f, i, range, enum)
    local v = range:float()
    if enum then return ("%s (%s)"):format(enum[v] or UNKNOWN_NAME, num(v)) end
    if f[3] == "bits" then return ("%s (%s)"):format(num(v), bitmask(range) or "not a bit mask") end
    local unit = unit_of(f, i)
    return is_unit(unit) and num(v) .. " " .. unit or num(v)
end

local function column_range(tvb, column, count)
    return tvb(HEADER + 8 * (column - 1), 8 * (count or 1))
end

-- Columns first..last, which no field of this layout covers, as raw doubles.
local function add_columns(tree, tvb, first, last)
    for c = first, last do
        local range = column_range(tvb, c)
        tree:add(pf.column, range, range:float(), ("column %d: %s"):format(c, num(range:float())))
    end
end

-- A field's elements; returns the last column it covers.
local function add_field(tree, tvb, f, column, enum)
    local name, count = f[1], f[2]
    local parent = tree
    if count > 1 then
        local unit = is_unit(f[3]) and " [" .. f[3] .. "]" or ""
        parent = tree:add(column_range(tvb, column, count), ("%s: %s%s"):format(name, f[4], unit))
    end
    for i = 0, count - 1 do
        local range = column_range(tvb, column + i)
        local label = count > 1 and ("%s[%d]"):format(name, i) or name
        parent:add(pf[name], range, range:float(), label .. ": " .. value_text(f, i, range, enum))
    end
    return column + count - 1
end

local function generation(doubles)
    for _, g in ipairs(GENERATIONS) do
        if doubles >= g[1] and doubles <= g[2] then return g[3] end
    end
end

-- One whole message (tvb holds exactly its bytes); returns its Info text.
local function dissect_message(tvb, tree)
    local size = tvb:len()
    local doubles = (size - HEADER) / 8
    local gen, versions = generation(doubles), VERSIONS[size]
    local t = tree:add(urrt, tvb())
    t:append_text((", %d bytes, %s, %s"):format(size, gen, versions or "no known controller"))
    local item = t:add(pf.length, tvb(0, HEADER))
    item:append_text((" bytes (%d doubles)"):format(doubles))
    t:add(pf.generation, gen):set_generated()
    if versions then
        t:add(pf.versions, versions):set_generated()
    else
        item:add_proto_expert_info(ex.unknown)
    end
    local shown = 0
    for _, row in ipairs(LAYOUT[gen]) do
        local name, column, fewest, enum = row[1], row[2], row[3], row[4]
        if doubles >= fewest then
            add_columns(t, tvb, shown + 1, column - 1)
            shown = add_field(t, tvb, FIELD[name], column, enum)
        end
    end
    add_columns(t, tvb, shown + 1, doubles)
    return ("%d B t=%s"):format(size, num(tvb(HEADER, 8):float()))
end

-- Why a size is not plausible (as urrt_packet_length()), or nil.
local function size_problem(size)
    if size < PACKET_MIN then return SIZE_SMALL end
    if (size - HEADER) % 8 ~= 0 then return SIZE_ALIGN end
    if size > PACKET_MAX then return SIZE_LARGE end
end

-- Robots by "address:port": the ones the heuristic found; the ports in
-- PORTS count by themselves. A stream's last size, for the resync rule.
local robots, last_size = {}, {}

local function endpoint(addr, port) return tostring(addr) .. ":" .. port end

local function from_robot(pinfo)
    if robots[endpoint(pinfo.src, pinfo.src_port)] then return true end
    if robots[endpoint(pinfo.dst, pinfo.dst_port)] then return false end
    return pinfo.src_port == pinfo.match_uint
end

-- As lib's framer after a bad header: the next offset whose header is a
-- known controller size or the stream's last size, else where fewer than
-- HEADER bytes remain.
local function resync(tvb, offset, stream)
    local len = tvb:len()
    for o = offset + 1, len - HEADER do
        local size = tvb(o, HEADER):int()
        if VERSIONS[size] or size == last_size[stream] then return o end
    end
    return math.max(offset + 1, len - HEADER + 1)
end

local function set_info(pinfo, text)
    if pinfo.private.urrt_info then
        pinfo.cols.info:append(", " .. text)
    else
        pinfo.cols.info:set(text)
        pinfo.private.urrt_info = "1"
    end
end

function urrt.dissector(tvb, pinfo, tree)
    local len = tvb:len()
    pinfo.cols.protocol = "URRT"
    if not from_robot(pinfo) then
        tree:add(urrt, tvb()):append_text((", %d bytes to the controller (URScript on %d)"):format(len, PORTS[1]))
        set_info(pinfo, ("to the controller, %d bytes"):format(len))
        return len
    end
    local stream = endpoint(pinfo.src, pinfo.src_port) .. ">" .. endpoint(pinfo.dst, pinfo.dst_port)
    local offset = 0
    while offset < len do
        local rest = len - offset
        if rest < HEADER then
            pinfo.desegment_offset, pinfo.desegment_len = offset, DESEGMENT_ONE_MORE_SEGMENT
            return len
        end
        local size = tvb(offset, HEADER):int()
        local problem = size_problem(size)
        if problem then
            local next_offset = resync(tvb, offset, stream)
            local t = tree:add(urrt, tvb(offset, next_offset - offset))
            t:append_text((", %d bytes skipped"):format(next_offset - offset))
            t:add(pf.length, tvb(offset, HEADER)):add_proto_expert_info(ex.size,
                ("%s (%d): %d bytes skipped to the next acceptable header"):format(problem, size, next_offset - offset))
            t:add(pf.skipped, tvb(offset, next_offset - offset))
            set_info(pinfo, ("%d bytes skipped"):format(next_offset - offset))
            offset = next_offset
        elseif rest < size then
            pinfo.desegment_offset, pinfo.desegment_len = offset, size - rest
            return len
        else
            last_size[stream] = size
            set_info(pinfo, dissect_message(tvb(offset, size):tvb(), tree))
            offset = offset + size
        end
    end
    return offset
end

function urrt.init()
    robots, last_size = {}, {}
end

local tcp_port = DissectorTable.get("tcp.port")
for _, port in ipairs(PORTS) do tcp_port:add(port, urrt) end

-- Other ports: a stream whose first segment starts with a known controller
-- size is taken for a robot's, and its connection for this dissector.
urrt:register_heuristic("tcp", function(tvb, pinfo, tree)
    if tvb:len() < HEADER or not VERSIONS[tvb(0, HEADER):int()] then return false end
    robots[endpoint(pinfo.src, pinfo.src_port)] = true
    pinfo.conversation = urrt
    urrt.dissector(tvb, pinfo, tree)
    return true
end)
