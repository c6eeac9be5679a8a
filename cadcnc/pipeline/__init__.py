"""A part's run, one pipeline for every caller (the command line, batch tasks, setups and
streams): plan (:mod:`.plan`, the one call into the operations), settle and judge
(:mod:`.exit_policy`: which verdict gives which exit code), write (:mod:`.operate`,
:mod:`.operation`) and stream (:mod:`.streaming`).

Each command's run is one module: :mod:`.operation` (path, pencil, finish),
:mod:`.setup_programs` (pencil in several setups), :mod:`.streaming`, :mod:`.apt_run`,
:mod:`.saved` (plot, verify), :mod:`.demo`, :mod:`.part_faces`. Nothing is imported here:
``cadcnc faces`` loads the part's modules only.
"""
