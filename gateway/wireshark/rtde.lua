-- SPDX-License-Identifier: MIT
-- The RTDE dissector (TCP 30004, any other port through Decode As). urrt_lua
-- prints RTDE_PORT, RTDE_HEADER, RTDE_LETTER, RTDE_TYPES and RTDE_VARS above
-- this from lib/urrt_rtde.h; num(), unit_of(), is_unit() and set_info() come
-- from dissector.lua, printed before it.
--
-- A TCP conversation is one session. What earlier packages of it set up says
-- how later ones read: the protocol version (1 until a V reply accepts the
-- version its request asked for), the recipe (the names of the last O
-- request with the types of its reply) and the input recipes (the names of
-- each I request with the id and types of its reply), by which a client's
-- data packages read. Wireshark dissects frames again in
-- any order, so the session as it stood before each frame is kept, and a
-- frame dissected again starts from that copy.

local rtde = Proto("urrt_rtde", "Universal Robots RTDE")

-- Setup inputs: lib/urrt_rtde.h, the reading side, has no constant for it.
local LETTER_I = string.byte("I")
local PACKAGES = {
    [RTDE_LETTER.V] = "protocol version", [RTDE_LETTER.v] = "controller version",
    [RTDE_LETTER.M] = "text message", [RTDE_LETTER.U] = "data package",
    [RTDE_LETTER.O] = "setup outputs", [RTDE_LETTER.S] = "start", [RTDE_LETTER.P] = "pause",
    [LETTER_I] = "setup inputs",
}
local TYPE_NAMES = {}
for letter, name in pairs(PACKAGES) do TYPE_NAMES[letter] = ("%s (%s)"):format(string.char(letter), name) end
local LEVELS = { [0] = "exception", [1] = "error", [2] = "warning", [3] = "info" }

local VAR = {}
for _, v in ipairs(RTDE_VARS) do VAR[v[1]] = v end

local rf = {
    size = ProtoField.uint16("urrt_rtde.size", "size", base.DEC, nil, nil,
        "Package size in bytes, the 3 header bytes included"),
    type = ProtoField.uint8("urrt_rtde.type", "type", base.HEX, TYPE_NAMES),
    protocol = ProtoField.uint8("urrt_rtde.protocol", "protocol in use", base.DEC, nil, nil,
        "The session's protocol version when this package came (1 until a V reply accepts another)"),
    version = ProtoField.uint16("urrt_rtde.version", "protocol version asked for"),
    accepted = ProtoField.uint8("urrt_rtde.accepted", "accepted", base.DEC, { [0] = "no", [1] = "yes" }),
    major = ProtoField.uint32("urrt_rtde.controller.major", "major"),
    minor = ProtoField.uint32("urrt_rtde.controller.minor", "minor"),
    bugfix = ProtoField.uint32("urrt_rtde.controller.bugfix", "bugfix"),
    build = ProtoField.uint32("urrt_rtde.controller.build", "build"),
    frequency = ProtoField.double("urrt_rtde.frequency", "frequency",
        "Rate asked for in Hz (0: the controller's maximum)"),
    names = ProtoField.string("urrt_rtde.names", "names"),
    name = ProtoField.string("urrt_rtde.name", "name"),
    types = ProtoField.string("urrt_rtde.types", "types"),
    var_type = ProtoField.string("urrt_rtde.var_type", "type"),
    recipe_id = ProtoField.uint8("urrt_rtde.recipe_id", "recipe id"),
    text_length = ProtoField.uint8("urrt_rtde.text_length", "text length"),
    text = ProtoField.string("urrt_rtde.text", "text"),
    source_length = ProtoField.uint8("urrt_rtde.source_length", "source length"),
    source = ProtoField.string("urrt_rtde.source", "source"),
    level = ProtoField.uint8("urrt_rtde.level", "level", base.DEC, LEVELS),
    payload = ProtoField.bytes("urrt_rtde.payload", "payload"),
}

-- One filterable field per variable (urrt_rtde.actual_q), of its element's
-- type; a vector's elements are each an item of the field. Names the table
-- does not know, or replies that give another type, use the "other" fields.
local function element_field(abbr, name, element, desc, enum)
    if element == "double" then return ProtoField.double(abbr, name, desc) end
    if element == "int32" then return ProtoField.int32(abbr, name, base.DEC, enum, nil, desc) end
    if element == "uint32" then return ProtoField.uint32(abbr, name, base.DEC, nil, nil, desc) end
    if element == "uint64" then return ProtoField.uint64(abbr, name, base.DEC, nil, nil, desc) end
    return ProtoField.uint8(abbr, name, base.DEC, nil, nil, desc)
end
local var_field, other_field = {}, {}
for _, v in ipairs(RTDE_VARS) do
    local name, type, field, unit, desc = v[1], v[2], v[3], v[4], v[5]
    local text = desc and ("%s (RealTime's %s)%s"):format(desc, field, is_unit(unit) and " [" .. unit .. "]" or "")
        or "RTDE variable " .. name
    var_field[name] = element_field("urrt_rtde." .. name, name, RTDE_TYPES[type][1], text, v[6])
    rf["var_" .. name] = var_field[name] -- prefixed: the variable "payload" is not rf.payload
end
for _, element in ipairs({ "double", "int32", "uint32", "uint64", "uint8", "bool" }) do
    other_field[element] = element_field("urrt_rtde.other." .. element, "other " .. element, element,
        "A variable urrt's table does not have with this type")
    rf["other_" .. element] = other_field[element]
end
rtde.fields = rf

local function warn(abbr, text) return ProtoExpert.new(abbr, text, expert.group.PROTOCOL, expert.severity.WARN) end
local rx = {
    not_found = warn("urrt_rtde.not_found", "Variable not found on this controller: the recipe is invalid"),
    in_use = warn("urrt_rtde.in_use",
        "Input in use by another client or an enabled fieldbus adapter: the input recipe is invalid"),
    bad_word = warn("urrt_rtde.bad_type", "A setup reply word that is no type: the recipe is invalid"),
    count = warn("urrt_rtde.type_count", "Setup reply: not one type per name asked for"),
    layout = warn("urrt_rtde.layout", "Package longer or shorter than its layout"),
    early = warn("urrt_rtde.data_early", "Data package before a recipe was set up"),
    recipe_id = warn("urrt_rtde.recipe_id", "Data package of another recipe id"),
    data_size = warn("urrt_rtde.data_size", "Data package size is not the recipe's"),
    input_recipe = warn("urrt_rtde.input_recipe", "Input data package of no input recipe of this connection"),
    unknown = warn("urrt_rtde.unknown_type", "Unknown package type"),
    size = ProtoExpert.new("urrt_rtde.size_small", "Size below the 3-byte header: the stream cannot be framed",
        expert.group.MALFORMED, expert.severity.ERROR),
}
rtde.experts = { rx.not_found, rx.in_use, rx.bad_word, rx.count, rx.layout, rx.early, rx.recipe_id, rx.data_size,
    rx.input_recipe, rx.unknown, rx.size }

-- ---- the session per conversation ----------------------------------------------

local sessions, before_frame = {}, {}
local session_in_frame -- the session the frame being dissected reads and changes

local function new_session() return { protocol = 1, inputs = {} } end

-- Shallow: the tables a session holds (names, recipe, inputs) are replaced, never changed.
local function copy(s)
    local c = {}
    for k, v in pairs(s) do c[k] = v end
    return c
end

-- The first call for a frame (pinfo.private lives as long as one dissection
-- of it) takes the session: live on the first pass, a copy when revisited.
local function session_of(pinfo, key)
    if pinfo.private.urrt_rtde_frame == nil then
        pinfo.private.urrt_rtde_frame = "1"
        if not pinfo.visited then
            sessions[key] = sessions[key] or new_session()
            before_frame[pinfo.number] = copy(sessions[key])
            session_in_frame = sessions[key]
        else
            session_in_frame = copy(before_frame[pinfo.number] or new_session())
        end
    end
    return session_in_frame
end

-- ---- package bodies ----------------------------------------------------------------

-- The payload must have n bytes (or, with at_least, n or more); else the
-- expert info and false.
local function layout_ok(t, tvb, n, at_least)
    local got = tvb:len() - RTDE_HEADER
    if got == n or (at_least and got > n) then return true end
    local item = got > 0 and t:add(rf.payload, tvb(RTDE_HEADER)) or t
    item:add_proto_expert_info(rx.layout, ("%d payload bytes, the layout has %s%d"):format(got,
        at_least and "at least " or "", n))
    return false
end

local function accepted(t, tvb)
    if not layout_ok(t, tvb, 1) then return "malformed" end
    t:add(rf.accepted, tvb(RTDE_HEADER, 1))
    return tvb(RTDE_HEADER, 1):uint() == 1 and "accepted" or "refused"
end

-- Comma-separated words from offset to the end, each as an item of field.
local function add_words(t, tvb, offset, all, one)
    local words = {}
    if offset >= tvb:len() then return words end
    local list = t:add(all, tvb(offset))
    local text = tvb(offset):string()
    local pos = 0
    for word in (text .. ","):gmatch("([^,]*),") do
        words[#words + 1] = { word = word, item = list:add(one, tvb(offset + pos, #word > 0 and #word or 0), word) }
        pos = pos + #word + 1
    end
    return words
end

local function names_of(words)
    local names = {}
    for i, w in ipairs(words) do names[i] = w.word end
    return names
end

local function setup_request(t, tvb, s, inputs)
    local offset = RTDE_HEADER
    if s.protocol >= 2 and not inputs then
        if not layout_ok(t, tvb, 8, true) then return "malformed" end
        t:add(rf.frequency, tvb(offset, 8))
        offset = offset + 8
    end
    local names = names_of(add_words(t, tvb, offset, rf.names, rf.name))
    if inputs then
        s.input_names = names
        return ("%d names"):format(#names)
    end
    s.names, s.recipe = names, nil
    if offset > RTDE_HEADER then return ("%d names at %s Hz"):format(#names, num(tvb(RTDE_HEADER, 8):float())) end
    return ("%d names"):format(#names)
end

-- The recipe of a setup reply: names of the request, types of the reply; nil
-- (and expert infos) when any word is NOT_FOUND, IN_USE (inputs) or no type,
-- or counts differ.
local function recipe_of(t, words, names, inputs)
    local recipe, ok = { bytes = 0 }, true
    for i, w in ipairs(words) do
        local coding = RTDE_TYPES[w.word]
        if w.word == "NOT_FOUND" then
            w.item:add_proto_expert_info(rx.not_found, ("%s: not found on this controller"):format(names[i] or "?"))
            ok = false
        elseif w.word == "IN_USE" and inputs then
            w.item:add_proto_expert_info(rx.in_use, ("%s: in use by another client or a fieldbus adapter"):format(
                names[i] or "?"))
            ok = false
        elseif coding == nil then
            w.item:add_proto_expert_info(rx.bad_word, ("%q is no type"):format(w.word))
            ok = false
        else
            recipe[i] = { name = names[i], type = w.word }
            recipe.bytes = recipe.bytes + coding[2] * coding[3]
        end
        if names[i] then w.item:append_text(" (" .. names[i] .. ")") end
    end
    if #words ~= #names then
        t:add_proto_expert_info(rx.count, ("%d types for %d names"):format(#words, #names))
        ok = false
    end
    return ok and recipe or nil
end

-- An input recipe's reply carries its id in both protocols (no layout
-- without it is described); a valid one (id not 0) is kept by its id, and
-- is the one a protocol 1 data package from the client (no id) is of.
local function input_setup_reply(t, tvb, s, id, words)
    local recipe = recipe_of(t, words, s.input_names or {}, true)
    if recipe and id ~= 0 then
        local inputs = {}
        for k, v in pairs(s.inputs) do inputs[k] = v end
        inputs[id] = recipe
        s.inputs, s.last_input = inputs, id
    end
    local what = recipe and id ~= 0 and "input recipe" or "input recipe INVALID"
    return ("%s %d, %d types"):format(what, id, #words)
end

local function setup_reply(t, tvb, s, inputs)
    local offset, id = RTDE_HEADER, nil
    if s.protocol >= 2 or inputs then
        if not layout_ok(t, tvb, 1, true) then return "malformed" end
        t:add(rf.recipe_id, tvb(offset, 1))
        id, offset = tvb(offset, 1):uint(), offset + 1
    end
    local words = add_words(t, tvb, offset, rf.types, rf.var_type)
    if inputs then return input_setup_reply(t, tvb, s, id, words) end
    s.recipe = recipe_of(t, words, s.names or {}, false)
    s.recipe_id = id
    local what = s.recipe and "recipe" or "recipe INVALID"
    return id and ("%s %d, %d types"):format(what, id, #words) or ("%s, %d types"):format(what, #words)
end

local function text_message(t, tvb, s, from_server)
    local len = tvb:len()
    if from_server and s.protocol < 2 then -- v1 from the controller: level, text to the end
        if not layout_ok(t, tvb, 1, true) then return "malformed" end
        t:add(rf.level, tvb(RTDE_HEADER, 1))
        local text = len > RTDE_HEADER + 1 and tvb(RTDE_HEADER + 1):string() or ""
        if #text > 0 then t:add(rf.text, tvb(RTDE_HEADER + 1)) end
        return ("%s: %s"):format(LEVELS[tvb(RTDE_HEADER, 1):uint()] or "level ?", text)
    end
    -- v2 (and v1 from the client): uint8 n, text, uint8 m, source, uint8 level
    local o = RTDE_HEADER
    local n = len > o and tvb(o, 1):uint()
    local m = n and len > o + 1 + n and tvb(o + 1 + n, 1):uint()
    if not m or not layout_ok(t, tvb, 3 + n + m) then
        if not m then layout_ok(t, tvb, 3) end
        return "malformed"
    end
    t:add(rf.text_length, tvb(o, 1))
    if n > 0 then t:add(rf.text, tvb(o + 1, n)) end
    t:add(rf.source_length, tvb(o + 1 + n, 1))
    if m > 0 then t:add(rf.source, tvb(o + 2 + n, m)) end
    t:add(rf.level, tvb(o + 2 + n + m, 1))
    local level = LEVELS[tvb(o + 2 + n + m, 1):uint()] or "level ?"
    return ("%s: %s%s"):format(level, n > 0 and tvb(o + 1, n):string() or "",
        m > 0 and " (" .. tvb(o + 2 + n, m):string() .. ")" or "")
end

-- ---- data packages -------------------------------------------------------------

local function element_value(element, range)
    if element == "double" then return range:float() end
    if element == "int32" then return range:int() end
    if element == "uint64" then return range:uint64() end
    return range:uint()
end

local function element_text(element, value, unit, enum)
    if element == "double" then return is_unit(unit) and num(value) .. " " .. unit or num(value) end
    if element == "bool" then return ("%s (%d)"):format(value ~= 0 and "true" or "false", value) end
    if enum then return ("%s (%d)"):format(enum[value] or UNKNOWN_NAME, value) end
    if element == "uint64" then return ("%s (0x%s)"):format(tostring(value), (value:tohex():upper():gsub("^0+(.)", "%1"))) end
    if unit == "bits" then return ("%d (0x%X)"):format(value, value) end
    return tostring(value)
end

-- One variable of a recipe at offset; returns the offset after it.
local function add_variable(t, tvb, offset, entry)
    local element, esize, count = table.unpack(RTDE_TYPES[entry.type])
    local known = VAR[entry.name]
    local field = var_field[entry.name]
    if not known or RTDE_TYPES[known[2]][1] ~= element then field = other_field[element] end
    local unit = known and known[4] or ""
    local enum = known and known[6]
    local parent = t
    if count > 1 then
        parent = t:add(tvb(offset, esize * count), ("%s: %s"):format(entry.name, entry.type))
    end
    for i = 0, count - 1 do
        local range = tvb(offset + i * esize, esize)
        local value = element_value(element, range)
        local label = count > 1 and ("%s[%d]"):format(entry.name, i) or entry.name
        local u = is_unit(unit) and unit_of({ entry.name, count, unit }, i) or ""
        parent:add(field, range, value, label .. ": " .. element_text(element, value, u, enum))
    end
    return offset + esize * count
end

-- A client's data package: the values of one of its input recipes, by the
-- id in protocol 2, the last one set up in protocol 1.
local function input_package(t, tvb, s)
    local offset, id = RTDE_HEADER, s.last_input
    if s.protocol >= 2 then
        if tvb:len() == offset then return layout_ok(t, tvb, 1, true) and "" or "malformed" end
        id = tvb(offset, 1):uint()
        local item = t:add(rf.recipe_id, tvb(offset, 1))
        if s.inputs[id] == nil then item:add_proto_expert_info(rx.input_recipe, ("input recipe %d"):format(id)) end
        offset = offset + 1
    end
    local recipe = id and s.inputs[id]
    if recipe == nil then
        local item = tvb:len() > offset and t:add(rf.payload, tvb(offset)) or t
        if s.protocol < 2 then item:add_proto_expert_info(rx.input_recipe, "no input recipe set up") end
        return ("no input recipe %s"):format(id and tostring(id) or "")
    end
    if tvb:len() ~= offset + recipe.bytes then
        t:add(rf.payload, tvb(RTDE_HEADER)):add_proto_expert_info(rx.data_size,
            ("%d bytes, input recipe %d's package has %d"):format(tvb:len(), id, offset + recipe.bytes))
        return ("input recipe %d: size not the recipe's"):format(id)
    end
    for _, entry in ipairs(recipe) do offset = add_variable(t, tvb, offset, entry) end
    return ("input recipe %d, %d values"):format(id, #recipe)
end

local function data_package(t, tvb, s)
    if s.recipe == nil then
        t:add(rf.payload, tvb(RTDE_HEADER)):add_proto_expert_info(rx.early)
        return "no recipe"
    end
    local offset = RTDE_HEADER
    if s.protocol >= 2 then
        local item = t:add(rf.recipe_id, tvb(offset, 1))
        if tvb(offset, 1):uint() ~= s.recipe_id then
            item:add_proto_expert_info(rx.recipe_id, ("recipe %d, the setup's is %d"):format(tvb(offset, 1):uint(),
                s.recipe_id or -1))
        end
        offset = offset + 1
    end
    if tvb:len() ~= offset + s.recipe.bytes then
        t:add(rf.payload, tvb(RTDE_HEADER)):add_proto_expert_info(rx.data_size,
            ("%d bytes, the recipe's package has %d"):format(tvb:len(), offset + s.recipe.bytes))
        return "size not the recipe's"
    end
    local info = ("%d values"):format(#s.recipe)
    for _, entry in ipairs(s.recipe) do
        if entry.name == "timestamp" and entry.type == "DOUBLE" then info = "t=" .. num(tvb(offset, 8):float()) end
        offset = add_variable(t, tvb, offset, entry)
    end
    return info
end

-- ---- dispatch ---------------------------------------------------------------------

local function controller_version(t, tvb)
    if not layout_ok(t, tvb, 16) then return "malformed" end
    local parts = {}
    for i, f in ipairs({ rf.major, rf.minor, rf.bugfix, rf.build }) do
        local range = tvb(RTDE_HEADER + 4 * (i - 1), 4)
        t:add(f, range)
        parts[i] = range:uint()
    end
    return table.concat(parts, ".")
end

local function protocol_version(t, tvb, s, from_server)
    if not from_server then
        if not layout_ok(t, tvb, 2) then return "malformed" end
        t:add(rf.version, tvb(RTDE_HEADER, 2))
        s.asked = tvb(RTDE_HEADER, 2):uint()
        return tostring(s.asked)
    end
    local answer = accepted(t, tvb)
    if answer == "accepted" and s.asked then s.protocol = s.asked end
    return ("%s %s"):format(tostring(s.asked or "?"), answer)
end

-- Each returns the Info text after the letter and the direction.
local BODY = {
    [RTDE_LETTER.V] = protocol_version,
    [RTDE_LETTER.v] = function(t, tvb, _, from_server)
        if from_server then return controller_version(t, tvb) end
        return layout_ok(t, tvb, 0) and "" or "malformed"
    end,
    [RTDE_LETTER.M] = text_message,
    [RTDE_LETTER.U] = function(t, tvb, s, from_server)
        if from_server then return data_package(t, tvb, s) end
        return input_package(t, tvb, s)
    end,
    [RTDE_LETTER.O] = function(t, tvb, s, from_server)
        if from_server then return setup_reply(t, tvb, s, false) end
        return setup_request(t, tvb, s, false)
    end,
    [LETTER_I] = function(t, tvb, s, from_server)
        if from_server then return setup_reply(t, tvb, s, true) end
        return setup_request(t, tvb, s, true)
    end,
}
local function start_or_pause(t, tvb, _, from_server)
    if from_server then return accepted(t, tvb) end
    return layout_ok(t, tvb, 0) and "" or "malformed"
end
BODY[RTDE_LETTER.S], BODY[RTDE_LETTER.P] = start_or_pause, start_or_pause

-- One whole package (tvb holds exactly its bytes); returns its Info text.
local function dissect_package(tvb, tree, s, from_server)
    local letter = tvb(2, 1):uint()
    local t = tree:add(rtde, tvb())
    local name = PACKAGES[letter] or "unknown type"
    local dir = from_server and "reply" or "request"
    if letter == RTDE_LETTER.U or letter == RTDE_LETTER.M then dir = from_server and "from controller" or "from client" end
    t:append_text((", %s %s, %d bytes"):format(name, dir, tvb:len()))
    t:add(rf.size, tvb(0, 2))
    local type_item = t:add(rf.type, tvb(2, 1))
    t:add(rf.protocol, s.protocol):set_generated()
    local body = BODY[letter]
    local text
    if body then
        text = body(t, tvb, s, from_server)
    else
        type_item:add_proto_expert_info(rx.unknown)
        if tvb:len() > RTDE_HEADER then t:add(rf.payload, tvb(RTDE_HEADER)) end
        text = ("0x%02x"):format(letter)
    end
    local letter_text = letter >= 32 and letter < 127 and string.char(letter) or "?"
    return ("%s %s%s"):format(letter_text, dir, text ~= "" and ": " .. text or "")
end

function rtde.dissector(tvb, pinfo, tree)
    pinfo.cols.protocol = "RTDE"
    local from_server = pinfo.src_port == pinfo.match_uint
    local server, client = endpoint(pinfo.src, pinfo.src_port), endpoint(pinfo.dst, pinfo.dst_port)
    if not from_server then server, client = client, server end
    local s = session_of(pinfo, server .. "<" .. client)
    local len, offset = tvb:len(), 0
    while offset < len do
        local rest = len - offset
        if rest < RTDE_HEADER then
            pinfo.desegment_offset, pinfo.desegment_len = offset, DESEGMENT_ONE_MORE_SEGMENT
            return len
        end
        local size = tvb(offset, 2):uint()
        if size < RTDE_HEADER then -- no size to frame the rest by
            local t = tree:add(rtde, tvb(offset))
            t:add(rf.size, tvb(offset, 2)):add_proto_expert_info(rx.size)
            t:add(rf.payload, tvb(offset))
            set_info(pinfo, ("size %d: %d bytes not framed"):format(size, rest))
            return len
        end
        if rest < size then
            pinfo.desegment_offset, pinfo.desegment_len = offset, size - rest
            return len
        end
        set_info(pinfo, dissect_package(tvb(offset, size):tvb(), tree, s, from_server))
        offset = offset + size
    end
    return offset
end

function rtde.init()
    sessions, before_frame, session_in_frame = {}, {}, nil
end

DissectorTable.get("tcp.port"):add(RTDE_PORT, rtde)
