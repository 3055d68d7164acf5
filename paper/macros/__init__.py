"""The paper's macros and tables, one module per section of paper/bodypoint.tex (make_macros.py runs them).
"""
