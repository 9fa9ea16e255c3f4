# gateway/: the programs. Each program is one .c file; shared code in modules.
