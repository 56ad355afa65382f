# surfcomp: the workbench class (FreeCAD executes this file when the GUI starts).
# The GUI modules are imported lazily in Initialize, so start-up stays fast.


class SurfCompWorkbench(Workbench):  # noqa: F821  (Workbench is provided by FreeCAD)
    MenuText = "SurfComp"
    ToolTip = "Compensate machining errors of free-form B-spline surfaces from measurements"

    def __init__(self):
        from surfcomp import paths

        self.__class__.Icon = paths.icon("surfcomp.svg")

    def Initialize(self):
        pass

    def GetClassName(self):
        return "Gui::PythonWorkbench"


Gui.addWorkbench(SurfCompWorkbench())  # noqa: F821
