(Drill program in the form pcb-gcode for EAGLE writes: a manual tool change is T<n>)
(followed by M00, the operator loads the drill while the machine waits)
G90
G21
M05
G00 Z5.0000
T01
M00
M03
G04 P2
G00 X10.0000 Y10.0000
G01 Z-1.8000 F100
G00 Z5.0000
G00 X20.0000 Y10.0000
G01 Z-1.8000
G00 Z5.0000
M05
T02
M00
M03
G04 P2
G00 X30.0000 Y15.0000
G01 Z-1.8000
G00 Z5.0000
M05
M30
