"""iteration"""
