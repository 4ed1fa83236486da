"""global_step"""
