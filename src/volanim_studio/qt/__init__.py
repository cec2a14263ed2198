"""The Qt layer: a main window that composes panels and controllers, all talking through the model.

main_window.py ........ MainWindow: the view, the panels, menus; owns the controllers
controller.py ......... what the window hands each controller; one way to report a user's error
files_controller.py ... open/save volumes, skeletons, bones, connectivity, projects
preview_controller.py . live and full previews, compare, export, poses (.trans/.tskel)
ownership_actions.py .. the Pose menu's ownership: the cube repaint, slices by owner, hang stray flesh on
connect_controller.py . the Connect menu: auto-connect and mirror
timeline_controller.py  load clips, play, step, key, scan for breakage, export frames
export_controller.py .. File → Export animated glTF: the posed body for any glTF viewer, in the worker
naming_controller.py .. F2 names a joint, Ctrl+F2 a whole chain
session_controller.py . autosave, crash recovery, the unsaved marker and "Save changes?"
worker.py ............. JobRunner/Worker: background jobs with progress, Cancel, clean shutdown
live_worker.py ........ LiveWorker: the live pictures' own thread, the newest pose first
bindings.py ........... two-way widget <-> settings bindings (signals blocked on write-back)
*_panel.py ............ one panel per file: bone_panel.py, connect_panel.py, display_panel.py,
                        pose_panel.py, reconstruct_panel.py, timeline_panel.py
dialogs and windows ... threshold_dialog.py, mapping_dialog.py, movie_dialog.py, propose_dialog.py,
                        scan_dialog.py, look_dialog.py, recovery_dialog.py, quicklook_window.py, slice_window.py,
                        transfer_editor.py (the thesis's Icol)
status_line.py ........ the status bar; verdict_label.py the last preview's verdict
fine_slider.py ........ FineSlider: the pose sliders, a degree per 5 pixels with Shift held
mode_keys.py .......... the mode letters work wherever the focus is
interactor.py ......... a pyvistaqt interactor closed without a stale wrapper; gui_gc.py: garbage
                        collected on the GUI thread only, never fully in a drag or a play
"""
