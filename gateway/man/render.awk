# SPDX-License-Identifier: MIT
# render.awk: a man page source (gateway/man/*.md, a small markdown) to troff.
#   % NAME SECTION "TITLE"    the .TH line (VERSION and DATE come from -v)
#   # HEADING                 a section (.SH)
#   ## HEADING                a subsection (.SS)
#   ### TERM                  a tagged paragraph (.TP): option or key; words
#                             starting with - or [ are bold, CAPITALS italic
#   - item                    a bullet
#       code                  (4 spaces) shown as it is
#   `code` in text            bold; *word* italic
function esc(s) { gsub(/\\/, "\\e", s); return s }
function inline(s,   out, i, c, code) {
    s = esc(s); out = ""
    while ((i = index(s, "`")) > 0) {
        out = out substr(s, 1, i - 1); s = substr(s, i + 1)
        c = index(s, "`"); if (c == 0) { out = out "`"; break }
        code = substr(s, 1, c - 1); gsub(/-/, "\\-", code)
        out = out "\\fB" code "\\fR"; s = substr(s, c + 1)
    }
    s = out s
    while (match(s, /\*[^* ][^*]*\*/)) s = substr(s, 1, RSTART - 1) "\\fI" substr(s, RSTART + 1, RLENGTH - 2) "\\fR" substr(s, RSTART + RLENGTH)
    if (s ~ /^[.']/) s = "\\&" s
    return s
}
function term(s,   n, w, i, out, t, sep) {
    n = split(esc(s), w, " "); out = ""
    for (i = 1; i <= n; i++) {
        t = w[i]; sep = ""
        if (t ~ /,$/) { sep = ","; t = substr(t, 1, length(t) - 1) }
        if (t ~ /^-/ || t ~ /^\[/) { gsub(/-/, "\\-", t); t = "\\fB" t "\\fR" }
        else if (t ~ /^[A-Z][A-Z_0-9.]*$/ && length(t) > 1) t = "\\fI" t "\\fR"
        else { gsub(/-/, "\\-", t); t = "\\fB" t "\\fR" }
        out = out (i > 1 ? " " : "") t sep
    }
    return out
}
function endcode() { if (code) { print ".fi"; print ".RE"; code = 0 } }
/^<!--.*-->$/ { c = $0; sub(/^<!-- */, "", c); sub(/ *-->$/, "", c); print ".\\\" " c; next }
/^% / {
    n = split($0, h, " ")
    title = $0; sub(/^% [^ ]+ [^ ]+ /, "", title)
    printf ".TH %s %s \"%s\" \"urrt %s\" %s\n", toupper(h[2]), h[3], date, version, title
    print ".\\\" Generated from gateway/man/" source " by gateway/man/render.awk: edit that file."
    next
}
/^    / && !/^    *$/ {
    if (!code) { print ".RS 4"; print ".nf"; code = 1 }
    s = esc(substr($0, 5)); if (s ~ /^[.']/) s = "\\&" s
    print s; next
}
/^$/ { if (code) { endcode() } else para = 1; next }
{ endcode() }
/^# /   { section = toupper(substr($0, 3)); print ".SH " section; para = 0; next }
section == "NAME" { s = esc($0); sub(/ - /, " \\- ", s); print s; next }
/^## /  { print ".SS " inline(substr($0, 4)); para = 0; next }
/^### / { print ".TP"; print term(substr($0, 5)); para = 0; next }
/^- /   { print ".IP \\(bu 2"; print inline(substr($0, 3)); para = 0; next }
{ if (para) { print ".PP"; para = 0 } print inline($0) }
END { endcode() }
