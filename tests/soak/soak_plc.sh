# SPDX-License-Identifier: MIT
# In the VM of tests/vm/run.sh, for make soak: the RTDE robot and its PLC
# (soak_plc.py: the simulator, both gateways, the PLC and its judge), for
# SOAK_MINUTES in phases of SOAK_PHASE_SECONDS. Python staged by
# tests/canopen/stage-python.sh. Its last line is "N passed, N failed".
ln -sf /t/py/bin/python3 /usr/bin/python3
export PYTHONHOME=/t/py
exec python3 soak_plc.py --minutes "$SOAK_MINUTES" --phase-seconds "$SOAK_PHASE_SECONDS" --out "$OUT"
