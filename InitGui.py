# SPDX-License-Identifier: LGPL-2.1-or-later
# surfcomp: the workbench class (FreeCAD executes this file when the GUI starts).
# The GUI modules are imported lazily in Initialize, so start-up stays fast; resource
# paths come from surfcomp.paths (this file is exec'd: no __file__ here).


class SurfCompWorkbench(Workbench):  # noqa: F821  (Workbench is provided by FreeCAD)
    MenuText = "SurfComp"
    ToolTip = "Compensate machining errors of free-form B-spline surfaces from measurements"

    def __init__(self):
        from surfcomp import paths

        self.__class__.Icon = paths.icon("surfcomp.svg")

    def Initialize(self):
        import os

        import FreeCADGui

        from surfcomp import paths
        from surfcomp.gui import commands, viewproviders

        commands.register()
        viewproviders.install_observer()
        items = list(commands.TOOLBAR)
        tools = [c for c in items if c is not None]
        self.appendToolbar("SurfComp", [c if c is not None else "Separator" for c in items])
        self.appendMenu("&SurfComp", [c if c is not None else "Separator" for c in items])
        # the Preferences dialog shows group "SurfComp" with the icon named
        # preferences-surfcomp in FreeCAD's icon paths
        FreeCADGui.addIconPath(os.path.join(paths.RESOURCES, "icons"))
        FreeCADGui.addPreferencePage(os.path.join(paths.RESOURCES, "ui", "preferences.ui"),
                                     "SurfComp")
        FreeCADGui.addLanguagePath(os.path.join(paths.RESOURCES, "translations"))
        self.commands = tools

    def Activated(self):
        pass

    def Deactivated(self):
        pass

    def GetClassName(self):
        return "Gui::PythonWorkbench"


Gui.addWorkbench(SurfCompWorkbench())  # noqa: F821
