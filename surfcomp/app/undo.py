# SPDX-License-Identifier: LGPL-2.1-or-later
"""One undo step: a FreeCAD document transaction that is committed, or aborted on any error.

The one transaction helper of surfcomp (commands, task panels, replace/restore)::

    with UndoStep(doc, "Replace Nominal by Compensation"):
        ...                       # an exception aborts: the document is as before

A task panel, whose step spans several user actions, calls :meth:`UndoStep.open`,
:meth:`UndoStep.commit` and :meth:`UndoStep.abort` itself.
"""


class UndoStep:
    """A named transaction of ``doc``.

    Parameters
    ----------
    doc : FreeCAD document
    label : str
        The name of the step in FreeCAD's Undo menu.
    rollback : callable, optional
        Puts back what the step changed when FreeCAD's own undo cannot (called before and
        after the abort: the abort may replay older values).
    """

    def __init__(self, doc, label, rollback=None):
        self.doc = doc
        self.label = label
        self.rollback = rollback

    def open(self):
        self.doc.openTransaction(self.label)
        return self

    def commit(self):
        self.doc.commitTransaction()

    def abort(self):
        if self.rollback is not None:
            self.rollback()
        self.doc.abortTransaction()
        if self.rollback is not None:
            self.rollback()

    def __enter__(self):
        return self.open()

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            self.commit()
        else:
            self.abort()
        return False
