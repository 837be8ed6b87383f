"""GRBL 1.1's error and alarm codes with their messages (gnea/grbl doc/csv).

And the firmware a controller's first words name (:func:`firmware`).
"""

from __future__ import annotations

import re

_BANNER = re.compile(r"Grbl (\d+)\.(\d+)(\S*)")
_OLD_STATUS = re.compile(r"<[A-Za-z]+,")


def firmware(line: str) -> str | None:
    """Why ``send`` cannot stream to the controller that said ``line``; ``None``: no reason.

    A banner of a GRBL older than 1.1 (``Grbl 0.9j ['$' for help]``, ``Grbl 0.8c``) or a
    status report in their format (``<Idle,MPos:…,WPos:…>``; GRBL 1.1 writes
    ``<Idle|MPos:…>``): camtool's GRBL link is GRBL 1.1's protocol (interface.md: status
    reports, ``Bf:`` buffer counts, ``error:N``, ``Hold:0``), which those do not speak.
    Versions 1.1 and later (FluidNC says ``Grbl 3.7``) pass.
    """
    banner = _BANNER.match(line)
    if banner is not None and (int(banner.group(1)), int(banner.group(2))) < (1, 1):
        version = banner.group(0).removeprefix("Grbl ")
        return f"the controller is GRBL {version} (its start-up line: {line.strip()!r})" + _OLD
    if _OLD_STATUS.match(line):
        return f"the controller answers in GRBL 0.9's status format ({line.strip()!r})" + _OLD
    return None


_OLD = (
    ": camtool's grbl link speaks GRBL 1.1's protocol (status reports, buffer counts, error "
    "codes), which GRBL before 1.1 does not speak; update the firmware to GRBL 1.1, or stream "
    "the program with a sender made for that version"
)

ERRORS: dict[int, tuple[str, str]] = {
    1: (
        "Expected command letter",
        ("G-code words consist of a letter and a value. Letter was not found."),
    ),
    2: (
        "Bad number format",
        ("Missing the expected G-code word value or numeric value format is not valid."),
    ),
    3: (
        "Invalid statement",
        ("Grbl '$' system command was not recognized or supported."),
    ),
    4: (
        "Value < 0",
        ("Negative value received for an expected positive value."),
    ),
    5: (
        "Setting disabled",
        ("Homing cycle failure. Homing is not enabled via settings."),
    ),
    6: (
        "Value < 3 usec",
        ("Minimum step pulse time must be greater than 3usec."),
    ),
    7: (
        "EEPROM read fail. Using defaults",
        ("An EEPROM read failed. Auto-restoring affected EEPROM to default values."),
    ),
    8: (
        "Not idle",
        (
            "Grbl '$' command cannot be used unless Grbl is IDLE. Ensures smooth operation "
            "during a job."
        ),
    ),
    9: (
        "G-code lock",
        ("G-code commands are locked out during alarm or jog state."),
    ),
    10: (
        "Homing not enabled",
        ("Soft limits cannot be enabled without homing also enabled."),
    ),
    11: (
        "Line overflow",
        ("Max characters per line exceeded. Received command line was not executed."),
    ),
    12: (
        "Step rate > 30kHz",
        ("Grbl '$' setting value cause the step rate to exceed the maximum supported."),
    ),
    13: (
        "Check Door",
        ("Safety door detected as opened and door state initiated."),
    ),
    14: (
        "Line length exceeded",
        ("Build info or startup line exceeded EEPROM line length limit. Line not stored."),
    ),
    15: (
        "Travel exceeded",
        ("Jog target exceeds machine travel. Jog command has been ignored."),
    ),
    16: (
        "Invalid jog command",
        ("Jog command has no '=' or contains prohibited g-code."),
    ),
    17: (
        "Setting disabled",
        ("Laser mode requires PWM output."),
    ),
    20: (
        "Unsupported command",
        ("Unsupported or invalid g-code command found in block."),
    ),
    21: (
        "Modal group violation",
        ("More than one g-code command from same modal group found in block."),
    ),
    22: (
        "Undefined feed rate",
        ("Feed rate has not yet been set or is undefined."),
    ),
    23: (
        "Invalid gcode ID:23",
        ("G-code command in block requires an integer value."),
    ),
    24: (
        "Invalid gcode ID:24",
        ("More than one g-code command that requires axis words found in block."),
    ),
    25: (
        "Invalid gcode ID:25",
        ("Repeated g-code word found in block."),
    ),
    26: (
        "Invalid gcode ID:26",
        (
            "No axis words found in block for g-code command or current modal state which "
            "requires them."
        ),
    ),
    27: (
        "Invalid gcode ID:27",
        ("Line number value is invalid."),
    ),
    28: (
        "Invalid gcode ID:28",
        ("G-code command is missing a required value word."),
    ),
    29: (
        "Invalid gcode ID:29",
        ("G59.x work coordinate systems are not supported."),
    ),
    30: (
        "Invalid gcode ID:30",
        ("G53 only allowed with G0 and G1 motion modes."),
    ),
    31: (
        "Invalid gcode ID:31",
        ("Axis words found in block when no command or current modal state uses them."),
    ),
    32: (
        "Invalid gcode ID:32",
        ("G2 and G3 arcs require at least one in-plane axis word."),
    ),
    33: (
        "Invalid gcode ID:33",
        ("Motion command target is invalid."),
    ),
    34: (
        "Invalid gcode ID:34",
        ("Arc radius value is invalid."),
    ),
    35: (
        "Invalid gcode ID:35",
        ("G2 and G3 arcs require at least one in-plane offset word."),
    ),
    36: (
        "Invalid gcode ID:36",
        ("Unused value words found in block."),
    ),
    37: (
        "Invalid gcode ID:37",
        ("G43.1 dynamic tool length offset is not assigned to configured tool length axis."),
    ),
    38: (
        "Invalid gcode ID:38",
        ("Tool number greater than max supported value."),
    ),
}
"""GRBL 1.1 ``error:N``: (v1.0 message, description), gnea/grbl doc/csv/error_codes_en_US.csv."""


ALARMS: dict[int, tuple[str, str]] = {
    1: (
        "Hard limit",
        (
            "Hard limit has been triggered. Machine position is likely lost due to sudden "
            "halt. Re-homing is highly recommended."
        ),
    ),
    2: (
        "Soft limit",
        (
            "Soft limit alarm. G-code motion target exceeds machine travel. Machine position "
            "retained. Alarm may be safely unlocked."
        ),
    ),
    3: (
        "Abort during cycle",
        (
            "Reset while in motion. Machine position is likely lost due to sudden halt. Re-"
            "homing is highly recommended."
        ),
    ),
    4: (
        "Probe fail",
        (
            "Probe fail. Probe is not in the expected initial state before starting probe "
            "cycle when G38.2 and G38.3 is not triggered and G38.4 and G38.5 is triggered."
        ),
    ),
    5: (
        "Probe fail",
        (
            "Probe fail. Probe did not contact the workpiece within the programmed travel for"
            " G38.2 and G38.4."
        ),
    ),
    6: (
        "Homing fail",
        ("Homing fail. The active homing cycle was reset."),
    ),
    7: (
        "Homing fail",
        ("Homing fail. Safety door was opened during homing cycle."),
    ),
    8: (
        "Homing fail",
        (
            "Homing fail. Pull off travel failed to clear limit switch. Try increasing pull-"
            "off setting or check wiring."
        ),
    ),
    9: (
        "Homing fail",
        (
            "Homing fail. Could not find limit switch within search distances. Try increasing"
            " max travel, decreasing pull-off distance, or check wiring."
        ),
    ),
    10: (
        "Homing fail",
        (
            "Homing fail. Second dual axis limit switch failed to trigger within configured "
            "search distance after first. Try increasing trigger fail distance or check "
            "wiring."
        ),
    ),
}
"""GRBL 1.1 ``ALARM:N``: (v1.0 message, description), gnea/grbl doc/csv/alarm_codes_en_US.csv."""
